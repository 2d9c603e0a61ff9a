// tickfx: run, check and study particle effects from the command line.
#include <tbb/global_control.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "app/Commands.h"
#include "io/effect/EffectSettings.h"
#include "io/util/AtomicFile.h"

namespace {

constexpr const char* kUsage =
    "usage: tickfx COMMAND [ARGS]\n"
    "\n"
    "commands:\n"
    "  run EFFECT.toml    simulate an effect and write per-frame caches\n"
    "  merge SHARD_DIR... --out DIR  merge the shards of a run (run --shard I/N) into the\n"
    "                     whole run's files\n"
    "  check EFFECT.toml  validate an effect and print lint warnings\n"
    "  study              the integrator study: three experiments against exact solutions\n"
    "  determinism EFFECT.toml  run an effect under many frame rates and thread counts and\n"
    "                     compare the state after every tick\n"
    "  bake-field KIND --out FILE.vdb  bake an analytic vector field (uniform, vortex, shear,\n"
    "                     curl-noise) into an OpenVDB file, or a sequence of them\n"
    "  preview EFFECT.toml  render an effect's frames to PNG\n"
    "\n"
    "`tickfx COMMAND --help` describes a command. Exit codes: 0 ok, 2 usage or effect errors,\n"
    "1 failure at run time.\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace tickfx::app;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? kExitUsage : kExitOk;
  }
  if (std::strcmp(argv[1], "--version") == 0) {
    std::printf("tickfx %s\n", TICKFX_VERSION);
    return kExitOk;
  }
  // The command line is its own host, and it asks for what `--threads N` says: TBB otherwise keeps
  // its workers to the core count, and a determinism check of 8 threads on 2 cores must really
  // run 8. Only a cap: systems of automatic concurrency still use one thread per core.
  const tbb::global_control threadLimit(tbb::global_control::max_allowed_parallelism,
                                        static_cast<std::size_t>(tickfx::io::kMaxThreads));
  // A file size limit (ulimit -f on a farm) then fails a write with EFBIG, which the writers
  // report by file name, instead of killing the process half-way through a file.
  std::signal(SIGXFSZ, SIG_IGN);
  const std::string command = argv[1];
  Arguments args(command, std::vector<std::string>(argv + 2, argv + argc));
  try {
    if (command == "run") return runCommand(args);
    if (command == "merge") return mergeCommand(args);
    if (command == "check") return checkCommand(args);
    if (command == "study") return studyCommand(args);
    if (command == "determinism") return determinismCommand(args);
    if (command == "bake-field") return bakeFieldCommand(args);
    if (command == "preview") return previewCommand(args);
    std::fprintf(stderr, "tickfx: unknown command '%s'\n\n%s", command.c_str(), kUsage);
    return kExitUsage;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "tickfx %s\n", e.what());
    return kExitUsage;
  } catch (const tickfx::io::WriteError& e) {
    std::fprintf(stderr, "%s\n", e.what());  // "PATH: error: cannot write (REASON)"
    return kExitFailure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tickfx %s: error: %s\n", command.c_str(), e.what());
    return kExitFailure;
  }
}
