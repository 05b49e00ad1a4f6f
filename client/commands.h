// The seep CLI's commands. Each returns the process exit code:
//   0 success; 1..16 the gRPC status code of a failed call (3 = bad input, 5 = no such job,
//   14 = server unreachable); 20 the watched job FAILED; 21 it was CANCELLED.
#pragma once

#include <string>

namespace seep::client {

inline constexpr int kExitJobFailed = 20;
inline constexpr int kExitJobCancelled = 21;

struct GlobalOptions {
  std::string server = "127.0.0.1:50051";
  double timeout_s = 10.0;
  bool json = false;
};

struct SubmitOptions {
  std::string scene_file;
  std::string name;
  std::string request_id;
  bool watch = false;
};

int Submit(const GlobalOptions& global, const SubmitOptions& options);
int Watch(const GlobalOptions& global, const std::string& job_id);
int Show(const GlobalOptions& global, const std::string& job_id);
int List(const GlobalOptions& global, unsigned limit);
int Health(const GlobalOptions& global);

}  // namespace seep::client
