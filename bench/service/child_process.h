// A program the service benches start and watch from outside, as an operator would: seepd and
// seep-worker run as child processes with their output in a file, and what they cost is read
// from /proc (CPU time, resident memory), not from inside.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace seep::bench {

class ChildProcess {
 public:
  ChildProcess() = default;
  // Starts argv[0] (a path) with its stdout and stderr in `output`; check started().
  ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& output);
  ChildProcess(ChildProcess&& other) noexcept;
  ChildProcess& operator=(ChildProcess&& other) noexcept;
  // Killed (SIGKILL) if still running: a bench that gives up leaves no process behind.
  ~ChildProcess();

  bool started() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  // Sends `signal` and waits; the wait status (waitpid's), or -1 when it was not running.
  int Stop(int signal);
  // User + system CPU seconds the process has used so far (/proc/<pid>/stat); -1 if unreadable.
  double CpuSeconds() const;
  // Resident set size in MiB (/proc/<pid>/status); 0 if unreadable.
  double RssMib() const;

 private:
  pid_t pid_ = -1;
};

// User + system CPU seconds process `pid` has used so far (/proc/<pid>/stat); -1 if unreadable.
double ProcessCpuSeconds(pid_t pid);

// The live processes whose parent is `parent` (seepd's worker processes).
std::vector<pid_t> ChildrenOf(pid_t parent);

// The port a seepd started with --port-file wrote there, waiting up to 30 s; -1 if none came.
int WaitForPortFile(const std::filesystem::path& file);

// True when a wait status says the process exited with status 0.
bool ExitedCleanly(int wait_status);

}  // namespace seep::bench
