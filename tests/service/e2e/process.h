// Test helpers that run the real binaries: a background server process and one-shot commands.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace seep::testing {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr, interleaved
};

// Runs argv to completion (no shell), capturing its output.
CommandResult RunCommand(const std::vector<std::string>& argv);

// A child process that is stopped (SIGTERM, then SIGKILL) when the object goes away.
class ChildProcess {
 public:
  ChildProcess() = default;
  explicit ChildProcess(const std::vector<std::string>& argv, const std::string& log_path);
  ChildProcess(ChildProcess&& other) noexcept : pid_(other.pid_) { other.pid_ = -1; }
  ChildProcess& operator=(ChildProcess&& other) noexcept {
    std::swap(pid_, other.pid_);
    return *this;
  }
  ~ChildProcess();

  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  // If the process has ended: its exit status (or 128 + signal), and it is no longer running();
  // else -1, without waiting.
  int PollExit();
  // Sends the signal and waits for the exit; returns the exit status (or 128 + signal).
  int Stop(int signal, std::chrono::seconds timeout = std::chrono::seconds(20));

 private:
  pid_t pid_ = -1;
};

// Waits until the file exists and holds a number; returns it, or -1 on timeout.
int WaitForPortFile(const std::string& path, std::chrono::seconds timeout);

}  // namespace seep::testing
