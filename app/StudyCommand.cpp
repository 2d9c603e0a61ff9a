// tickfx study: the integrator study's tables, one CSV per experiment, and its figures.
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/Commands.h"
#include "app/IntegratorStudy.h"
#include "app/StudyPlotsScript.h"

extern char** environ;

namespace tickfx::app {
namespace {

// Exit status of the plotting script when matplotlib cannot be imported (app/study_plots.py).
constexpr int kScriptMissingMatplotlib = 3;

const char* const kPlotsHelp =
    "plotting needs Python 3 with matplotlib (Debian: apt-get install python3-matplotlib)";

// Debian's own interpreter, whatever is first on PATH; TICKFX_PYTHON names another.
std::string pythonInterpreter() {
  const char* chosen = std::getenv("TICKFX_PYTHON");
  return chosen != nullptr && *chosen != '\0' ? chosen : "/usr/bin/python3";
}

// Runs the embedded plotting script on the series in `dir`; throws std::runtime_error saying what
// to install when Python or matplotlib is missing, and the script's exit status otherwise.
void drawPlots(const std::string& dir) {
  const std::string python = pythonInterpreter();
  std::vector<std::string> words = {python, "-c", kStudyPlotsScript, dir};
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = ::posix_spawn(&pid, python.c_str(), nullptr, nullptr, argv.data(), environ);
  if (spawned != 0) {
    throw std::runtime_error("cannot run " + python + " (" + std::strerror(spawned) +
                             "): " + kPlotsHelp);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("cannot wait for " + python);
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  if (WIFEXITED(status) && WEXITSTATUS(status) == kScriptMissingMatplotlib) {
    throw std::runtime_error(python + " has no matplotlib: " + kPlotsHelp);
  }
  // 127: posix_spawn found no program to execute after the fork.
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127) {
    throw std::runtime_error("cannot run " + python + ": " + kPlotsHelp);
  }
  throw std::runtime_error("the plotting script failed (" + python + ", " +
                           (WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                                              : "signal " + std::to_string(WTERMSIG(status))) +
                           ")");
}

}  // namespace

int studyCommand(Arguments& args) {
  if (args.flag("--help")) {
    std::fputs(
        "usage: tickfx study [--out DIR] [--plots DIR]\n"
        "\n"
        "Runs every integrator through three experiments with exact solutions, at dt = 1/1000,\n"
        "1/144, 1/60, 1/30 and 1/20 s: constant acceleration (position error at 0.5 s and 10 s),\n"
        "the harmonic oscillator (position error and energy after 20 s at dt = 1/20 and 1/4 s),\n"
        "and a periodic wind of 150 m/s^2 at 4 Hz and 16 Hz (position after 2 s). Prints the\n"
        "tables and writes constant_acceleration.csv, oscillator.csv and wind.csv into DIR\n"
        "(default out/study).\n"
        "\n"
        "--plots DIR also writes every tick of the runs the figures show (series_*.csv) and\n"
        "draws them with matplotlib (Debian's /usr/bin/python3, or $TICKFX_PYTHON):\n"
        "constant_acceleration.png (position and error against time, every integrator and\n"
        "step rate), oscillator.png (position, energy and phase portrait at dt = 1/20 and\n"
        "1/4 s) and wind.png (the 16 Hz wind at 20 Hz against 1000 Hz).\n",
        stdout);
    return kExitOk;
  }
  const std::string dir = args.value("--out").value_or("out/study");
  const std::optional<std::string> plots = args.value("--plots");
  args.positionals(0, "no positional arguments: tickfx study [--out DIR] [--plots DIR]");
  const StudyResults results = runIntegratorStudy();
  printStudy(results, stdout);
  std::printf("\n");
  for (const auto& path : writeStudyCsv(results, dir))
    std::printf("wrote %s\n", path.string().c_str());
  if (plots) {
    for (const auto& path : writeStudySeriesCsv({}, *plots))
      std::printf("wrote %s\n", path.string().c_str());
    std::fflush(stdout);  // before the script's own lines
    drawPlots(*plots);
  }
  return kExitOk;
}

}  // namespace tickfx::app
