// tickfx study: the integrator study's tables, and one CSV per experiment.
#include <cstdio>

#include "app/Commands.h"
#include "app/IntegratorStudy.h"

namespace tickfx::app {

int studyCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(
        "usage: tickfx study [--out DIR]\n"
        "\n"
        "Runs every integrator through three experiments with exact solutions, at dt = 1/1000,\n"
        "1/144, 1/60, 1/30 and 1/20 s: constant acceleration (position error at 0.5 s and 10 s),\n"
        "the harmonic oscillator (position error and energy after 20 s at dt = 1/20 and 1/4 s),\n"
        "and a periodic wind of 150 m/s^2 at 4 Hz and 16 Hz (position after 2 s). Prints the\n"
        "tables and writes constant_acceleration.csv, oscillator.csv and wind.csv into DIR\n"
        "(default out/study).\n",
        stdout);
    return kExitOk;
  }
  const std::string dir = args.value("--out").value_or("out/study");
  args.positionals(0, "no positional arguments: tickfx study [--out DIR]");
  const StudyResults results = runIntegratorStudy();
  printStudy(results, stdout);
  std::printf("\n");
  for (const auto& path : writeStudyCsv(results, dir))
    std::printf("wrote %s\n", path.string().c_str());
  return kExitOk;
}

}  // namespace tickfx::app
