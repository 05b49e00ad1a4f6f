// RunnerFlags: the command-line flags of the job runner that seepd and seep-worker share
// (threads per job, lease, checkpoint cadence, log level), declared once and turned into
// JobRunnerOptions once, so that both run jobs alike.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "jobs/job_runner.h"

namespace seep::service {

struct RunnerFlags {
  int workers = 1;
  int threads_per_job = 0;  // 0: the cores shared out among the workers
  double lease_s = 30.0;
  double checkpoint_interval_s = 30.0;
  std::uint64_t checkpoint_every_steps = 0;
  std::uint32_t checkpoints_kept = 3;
  std::string log_level = "info";
};

// Adds --threads-per-job, --log-level, --checkpoint-interval-s, --checkpoint-every-steps,
// --checkpoints-kept and --lease-s (with `lease_help`: what an expired lease means for the
// program). --workers differs (seepd allows 0) and is left to the caller.
void AddRunnerFlags(CLI::App& app, RunnerFlags& flags, const std::string& lease_help);

// The same flags as a seep-worker command line takes them (seepd passes its own on to the worker
// processes it starts, and to those its batch jobs start).
std::vector<std::string> RunnerFlagArgs(const RunnerFlags& flags);

// The runner's options from the flags: workers, threads per job, lease and its renewal
// interval (several per lease), and the checkpoint policy (on).
JobRunnerOptions RunnerOptionsFrom(const RunnerFlags& flags);

}  // namespace seep::service
