// RunCommand: runs a program (the batch system's sbatch, squeue, scancel) as a child process and
// collects what it printed, without a shell: the arguments reach it as they are, so nothing in a
// job name or flag can be read as shell syntax.
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <vector>

#include "seep/core/status.h"

namespace seep::service {

struct CommandOutput {
  int exit_code = 0;  // the program's exit status (128 + N when killed by signal N)
  std::string out;
  std::string err;
};

// Runs argv[0] (looked up in PATH) with argv, its environment this process's plus `env` (which
// wins). A program that cannot be started, or runs longer than `timeout` (it is then killed),
// is an UNAVAILABLE error naming it; otherwise its exit status and output, whatever the status.
// The child starts with no signal blocked, whatever the calling thread blocks.
core::Result<CommandOutput> RunCommand(const std::vector<std::string>& argv,
                                       const std::map<std::string, std::string>& env,
                                       std::chrono::milliseconds timeout);

}  // namespace seep::service
