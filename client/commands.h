// The seep CLI's commands. Each returns the process exit code:
//   0 success; 1..16 the gRPC status code of a failed call (3 = bad input, 5 = no such job,
//   14 = server unreachable); 20 the watched job FAILED; 21 it was CANCELLED; 64 a wrong command
//   line (kExitCodeHelp below is the table `seep --help` prints).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "connection.h"

namespace seep::client {

inline constexpr int kExitJobFailed = 20;
inline constexpr int kExitJobCancelled = 21;
inline constexpr int kExitUsage = 64;  // EX_USAGE of sysexits.h: outside the gRPC codes 0..16

inline constexpr const char* kExitCodeHelp =
    "Exit codes:\n"
    "  0   success (watch: the job SUCCEEDED)\n"
    "  3   bad input: a scene file that does not parse (FILE:LINE:COL) or that the server\n"
    "      rejects (FILE:LINE: scene.<field>: reason), a bad flag value\n"
    "  5   no such job (or sweep)\n"
    "  6   the request id was already used for another scene\n"
    "  9   the job is in the wrong state for the command (e.g. resume or delete a running job)\n"
    "  14  server unreachable (or the call timed out: --timeout)\n"
    "  16  missing or wrong token\n"
    "  1-16 any other gRPC status code of the failed call\n"
    "  20  the watched job FAILED (sweep submit --watch: one of its jobs)\n"
    "  21  the watched job was CANCELLED (sweep: one was, and none FAILED)\n"
    "  64  wrong command line (unknown option, missing argument)\n"
    "With --json, stdout holds one JSON document (messages go to stderr).\n"
    "Environment: SEEP_SERVER (--server), SEEP_TOKEN (--token).";

// The server, token and TLS options (connection.h), and what the CLI adds to them.
struct GlobalOptions : Connection {
  double timeout_s = 10.0;
  bool json = false;
};

// Reads --token-file and --tls-ca and checks the token; returns the exit code (0 = fine) after
// printing what is wrong.
int LoadCredentials(GlobalOptions* global);

struct SubmitOptions {
  std::string scene_file;
  std::string name;
  std::string request_id;
  int priority = 0;
  std::vector<std::string> labels;  // KEY=VALUE
  bool watch = false;
  // seep fork: the job whose checkpoint the scene continues from, and the checkpoint's step
  // (unset: the newest).
  std::string from_job_id;
  std::optional<std::uint64_t> from_step;
};

// Queues a scene file; with from_job_id, as a fork of that job (seep fork).
int Submit(const GlobalOptions& global, const SubmitOptions& options);
int Watch(const GlobalOptions& global, const std::string& job_id);
int Show(const GlobalOptions& global, const std::string& job_id);
struct ListOptions {
  unsigned limit = 50;
  std::vector<std::string> states;  // queued, running, succeeded, failed, cancelled (any case)
  std::string name_contains;
  std::vector<std::string> kinds;   // simulation, calibration (any case)
  std::vector<std::string> labels;  // KEY=VALUE: jobs carrying every one
};

int List(const GlobalOptions& global, const ListOptions& options);
// Cancels a job: a QUEUED job at once, a RUNNING one at its next step.
int Cancel(const GlobalOptions& global, const std::string& job_id);
// Queues a FAILED or CANCELLED job again as a new attempt.
int Resume(const GlobalOptions& global, const std::string& job_id);
// The metrics of a SUCCEEDED job, as a table or JSON.
int Result(const GlobalOptions& global, const std::string& job_id);
int Health(const GlobalOptions& global);

}  // namespace seep::client
