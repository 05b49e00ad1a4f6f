#include "jobs/runner_flags.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "seep/core/threads.h"

namespace seep::service {

void AddRunnerFlags(CLI::App& app, RunnerFlags& flags, const std::string& lease_help) {
  app.add_option("--threads-per-job", flags.threads_per_job,
                 "threads of each running job's parallel loops (default: the cores / --workers; "
                 "results do not depend on it)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--log-level", flags.log_level, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}))
      ->capture_default_str();
  app.add_option("--checkpoint-interval-s", flags.checkpoint_interval_s,
                 "wall seconds between two checkpoints of a running job (0 = no time trigger)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  app.add_option("--checkpoint-every-steps", flags.checkpoint_every_steps,
                 "steps between two checkpoints of a running job (0 = no step trigger)")
      ->capture_default_str();
  app.add_option("--checkpoints-kept", flags.checkpoints_kept,
                 "newest checkpoint files kept per job (in seepd's data folder)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--lease-s", flags.lease_s, lease_help)
      ->check(CLI::Range(0.5, 86400.0))
      ->capture_default_str();
}

std::vector<std::string> RunnerFlagArgs(const RunnerFlags& flags) {
  return {"--threads-per-job",
          std::to_string(std::max(1, flags.threads_per_job)),
          "--lease-s",
          fmt::format("{}", flags.lease_s),
          "--checkpoint-interval-s",
          fmt::format("{}", flags.checkpoint_interval_s),
          "--checkpoint-every-steps",
          std::to_string(flags.checkpoint_every_steps),
          "--checkpoints-kept",
          std::to_string(flags.checkpoints_kept),
          "--log-level",
          flags.log_level};
}

JobRunnerOptions RunnerOptionsFrom(const RunnerFlags& flags) {
  JobRunnerOptions options;
  options.workers = flags.workers;
  options.threads_per_job =
      flags.threads_per_job > 0 ? flags.threads_per_job : core::CoreThreadsPerJob(flags.workers);
  options.lease_duration =
      std::chrono::milliseconds(static_cast<std::int64_t>(flags.lease_s * 1000));
  // Renewals (and seepd's look for expired leases) several times per lease.
  options.heartbeat_interval =
      std::min(std::chrono::milliseconds(2000), options.lease_duration / 4);
  options.checkpoints.enabled = true;
  options.checkpoints.every_steps = flags.checkpoint_every_steps;
  options.checkpoints.interval =
      std::chrono::milliseconds(static_cast<std::int64_t>(flags.checkpoint_interval_s * 1000));
  options.checkpoints.keep = flags.checkpoints_kept;
  return options;
}

}  // namespace seep::service
