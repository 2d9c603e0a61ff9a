// The subcommands of `tickfx`. Each returns the process exit code: 0 ok, 2 usage or effect
// errors (nothing written), 1 failure at run time.
#pragma once

#include "app/Arguments.h"

namespace tickfx::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;

int runCommand(Arguments& args);
int mergeCommand(Arguments& args);
int checkCommand(Arguments& args);
int studyCommand(Arguments& args);
int determinismCommand(Arguments& args);
int bakeFieldCommand(Arguments& args);
int previewCommand(Arguments& args);

}  // namespace tickfx::app
