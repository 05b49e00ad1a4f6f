#include "executor/slurm_executor.h"

#include <fmt/format.h>
#include <sys/stat.h>

#include <algorithm>
#include <map>
#include <sstream>

#include "executor/command_runner.h"
#include "jobs/wall_clock.h"
#include "store/durable_files.h"

namespace seep::service {
namespace {

// One argument of the worker script, quoted for sh: nothing in it is expanded.
std::string ShellQuoted(const std::string& arg) {
  std::string quoted = "'";
  for (const char c : arg) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

std::string Trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
}

// What squeue says of one job.
struct SeenJob {
  std::string state;
  std::string node;
};

// squeue --format=%i|%T|%N lines: id, state, node list (empty while pending).
std::map<std::string, SeenJob> ParseSqueue(const std::string& out) {
  std::map<std::string, SeenJob> seen;
  std::istringstream lines(out);
  std::string line;
  while (std::getline(lines, line)) {
    const auto first = line.find('|');
    const auto second = first == std::string::npos ? first : line.find('|', first + 1);
    if (second == std::string::npos) continue;
    seen[Trimmed(line.substr(0, first))] = {Trimmed(line.substr(first + 1, second - first - 1)),
                                            Trimmed(line.substr(second + 1))};
  }
  return seen;
}

std::string FirstLine(const std::string& text) { return Trimmed(text.substr(0, text.find('\n'))); }

}  // namespace

SlurmExecutor::SlurmExecutor(JobStore& store, std::filesystem::path data_dir,
                             SlurmExecutorOptions options, std::shared_ptr<spdlog::logger> logger)
    : store_(store),
      slurm_dir_(data_dir / "slurm"),
      script_path_(slurm_dir_ / "seep-worker.sbatch"),
      options_(std::move(options)),
      logger_(std::move(logger)) {
  plan_options_.workers_per_job = std::max(1, options_.pack);
  plan_options_.max_jobs_per_worker = options_.pack == 0 ? 1 : 0;
  plan_options_.max_live = options_.max_batch_jobs;
  if (options_.output.empty()) options_.output = (slurm_dir_ / "seep-worker-%j.out").string();
}

SlurmExecutor::~SlurmExecutor() { Stop(); }

std::string SlurmExecutor::ScriptText() const {
  std::vector<std::string> args = {options_.worker_path,
                                   "--server",
                                   options_.server,
                                   "--workers",
                                   std::to_string(plan_options_.workers_per_job),
                                   "--max-jobs",
                                   std::to_string(plan_options_.max_jobs_per_worker),
                                   "--exit-when-idle-s",
                                   fmt::format("{}", options_.exit_when_idle_s)};
  const std::vector<std::string> runner = RunnerFlagArgs(options_.runner);
  args.insert(args.end(), runner.begin(), runner.end());
  args.insert(args.end(), options_.worker_args.begin(), options_.worker_args.end());
  std::string line = "exec";
  for (const std::string& arg : args) line += " " + ShellQuoted(arg);
  // The name is expanded by the job's shell: each worker's leases carry its Slurm job id.
  line += " --name \"slurm-${SLURM_JOB_ID:-unknown}\"";
  return fmt::format(
      "#!/bin/sh\n"
      "# Written by seepd --executor slurm at its start (and again at every start): one "
      "seep-worker\n"
      "# leasing jobs from the coordinator over gRPC. SIGTERM (scancel, preemption, the time "
      "limit\n"
      "# less the grace) makes it checkpoint its job and give it back before it exits.\n"
      "{}\n",
      line);
}

core::Status SlurmExecutor::Start() {
  if (options_.worker_path.empty() || options_.server.empty()) {
    return core::InvalidArgument("slurm executor: the worker path and server address are needed");
  }
  for (const char* program : {"sbatch", "squeue", "scancel"}) {
    auto version = RunCommand({program, "--version"}, {}, options_.command_timeout);
    if (!version.ok() || version->exit_code != 0) {
      return core::FailedPrecondition(fmt::format(
          "--executor slurm: {} does not answer ({}); install Slurm's client commands on this "
          "host and put them on PATH",
          program,
          version.ok() ? FirstLine(version->err + version->out) : version.status().message()));
    }
  }
  SEEP_RETURN_IF_ERROR(CreateDirectoriesDurably(slurm_dir_));
  SEEP_RETURN_IF_ERROR(WriteFileDurably(script_path_, ScriptText()));
  ::chmod(script_path_.c_str(), 0700);
  // What every batch job will be submitted with, checked by Slurm now (a partition that does not
  // exist, a time over its limit, a bad --slurm-extra): refused at start, not on every round.
  auto tried = RunCommand(SbatchArgv(/*test_only=*/true), {}, options_.command_timeout);
  if (!tried.ok() || tried->exit_code != 0) {
    const std::string why = tried.ok() ? FirstLine(tried->err.empty() ? tried->out : tried->err)
                                       : tried.status().message();
    // A controller that is down now may be up at the next round: that is no reason not to serve.
    if (why.find("contact slurm controller") == std::string::npos) {
      return core::FailedPrecondition(fmt::format(
          "--executor slurm: Slurm refuses the workers' batch jobs (sbatch --test-only): {}", why));
    }
    logger_->warn("slurm executor: {}; submitting when it answers", why);
  }
  logger_->info(
      "slurm executor: {} (partition {}, time {}), workers dial {}, at most {} batch jobs, "
      "script {}",
      options_.pack == 0
          ? std::string("one batch job per seep job")
          : fmt::format("{} workers per batch job until the queue is empty", options_.pack),
      options_.partition.empty() ? "default" : options_.partition,
      options_.time_limit.empty() ? "default" : options_.time_limit, options_.server,
      options_.max_batch_jobs, script_path_.string());
  thread_ = std::jthread([this](const std::stop_token& stop) { Loop(stop); });
  return core::Status::Ok();
}

void SlurmExecutor::Stop() {
  if (!thread_.joinable()) return;
  thread_.request_stop();
  wake_.notify_all();
  thread_.join();
}

void SlurmExecutor::Wake() {
  {
    std::lock_guard lock(mutex_);
    woken_ = true;
  }
  wake_.notify_all();
}

void SlurmExecutor::Loop(const std::stop_token& stop) {
  while (!stop.stop_requested()) {
    ReconcileOnce();
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, stop, options_.poll_interval, [this] { return woken_; });
    woken_ = false;
  }
}

std::optional<std::vector<BatchJobRecord>> SlurmExecutor::RefreshStates() {
  auto live = store_.LiveBatchJobs();
  if (!live.ok()) {
    logger_->warn("slurm executor: batch jobs not read: {}", live.status().ToString());
    return std::nullopt;
  }
  if (live->empty()) return std::move(*live);
  auto listed = RunCommand({"squeue", "--noheader", "--me", "--states=all", "--format=%i|%T|%N"},
                           {}, options_.command_timeout);
  if (!listed.ok() || listed->exit_code != 0) {
    logger_->warn("slurm executor: squeue failed ({}); states kept as they were",
                  listed.ok() ? FirstLine(listed->err) : listed.status().message());
    return std::nullopt;
  }
  const std::map<std::string, SeenJob> seen = ParseSqueue(listed->out);
  for (BatchJobRecord& batch : *live) {
    const auto it = seen.find(batch.id);
    // Gone from squeue: it ended long enough ago for the controller to forget it.
    const SeenJob now = it == seen.end() ? SeenJob{"ENDED", ""} : it->second;
    const bool ended = IsEndedBatchState(now.state);
    if (now.state == batch.state && (now.node.empty() || now.node == batch.node) && !ended) {
      continue;
    }
    const std::optional<std::int64_t> ended_at =
        ended ? std::optional<std::int64_t>(NowMs()) : std::nullopt;
    if (auto updated = store_.UpdateBatchJob(batch.id, now.state, now.node, ended_at);
        !updated.ok()) {
      logger_->warn("slurm executor: batch job {} not updated: {}", batch.id, updated.ToString());
      continue;
    }
    if (now.state != batch.state) {
      logger_->info("slurm executor: batch job {} {}{}", batch.id, now.state,
                    now.node.empty() ? "" : " on " + now.node);
    }
    batch.state = now.state;
    if (!now.node.empty()) batch.node = now.node;
    batch.ended_at_ms = ended_at;
  }
  return std::move(*live);
}

std::vector<std::string> SlurmExecutor::SbatchArgv(bool test_only) const {
  const int cpus = plan_options_.workers_per_job * std::max(1, options_.runner.threads_per_job);
  std::vector<std::string> argv = {"sbatch",
                                   test_only ? "--test-only" : "--parsable",
                                   "--job-name=seep-worker",
                                   "--requeue",
                                   fmt::format("--signal=B:TERM@{}", options_.signal_grace_s),
                                   "--ntasks=1",
                                   fmt::format("--cpus-per-task={}", cpus),
                                   "--output=" + options_.output,
                                   "--export=ALL"};
  if (!options_.partition.empty()) argv.push_back("--partition=" + options_.partition);
  if (!options_.time_limit.empty()) argv.push_back("--time=" + options_.time_limit);
  argv.insert(argv.end(), options_.extra.begin(), options_.extra.end());
  argv.push_back(script_path_.string());
  return argv;
}

core::Result<std::string> SlurmExecutor::Submit() {
  const std::vector<std::string> argv = SbatchArgv(/*test_only=*/false);
  std::map<std::string, std::string> env;
  if (!options_.token.empty()) env["SEEP_TOKEN"] = options_.token;  // exported to the job
  SEEP_ASSIGN_OR_RETURN(const CommandOutput out, RunCommand(argv, env, options_.command_timeout));
  const std::string first_line = FirstLine(out.out);  // "<id>" or "<id>;<cluster>"
  const std::string id = first_line.substr(0, first_line.find(';'));
  if (out.exit_code != 0 || id.empty() ||
      id.find_first_not_of("0123456789_") != std::string::npos) {
    return core::Unavailable(fmt::format("sbatch failed (exit {}): {}", out.exit_code,
                                         FirstLine(out.err.empty() ? out.out : out.err)));
  }
  BatchJobRecord batch;
  batch.id = id;
  batch.workers = plan_options_.workers_per_job;
  batch.max_jobs = plan_options_.max_jobs_per_worker;
  batch.state = "PENDING";
  batch.submitted_at_ms = NowMs();
  SEEP_RETURN_IF_ERROR(store_.InsertBatchJob(batch));
  return id;
}

void SlurmExecutor::Cancel(const std::string& batch_job_id, const char* why) {
  auto out = RunCommand({"scancel", batch_job_id}, {}, options_.command_timeout);
  if (!out.ok() || out->exit_code != 0) {
    logger_->warn("slurm executor: scancel {} failed: {}", batch_job_id,
                  out.ok() ? FirstLine(out->err) : out.status().message());
    return;
  }
  logger_->info("slurm executor: scancelled batch job {} ({})", batch_job_id, why);
}

void SlurmExecutor::ReconcileOnce() {
  const std::optional<std::vector<BatchJobRecord>> live = RefreshStates();
  if (!live) return;
  auto demand = store_.BatchDemandNow();
  if (!demand.ok()) {
    logger_->warn("slurm executor: the queue not read: {}", demand.status().ToString());
    return;
  }
  const BatchPlan plan = PlanBatchJobs(*demand, *live, plan_options_);
  for (const std::string& id : plan.cancel) {
    const auto use = demand->by_batch_job.find(id);
    Cancel(id, use != demand->by_batch_job.end() && use->second.cancel_requested > 0
                   ? "its job was cancelled"
                   : "not needed: fewer jobs are queued");
  }
  // No job starts on a low disk (store/free_space.h): a worker sent now would find none to claim.
  if (plan.submit > 0 && store_.free_space().Low()) return;
  for (int i = 0; i < plan.submit; ++i) {
    auto submitted = Submit();
    if (!submitted.ok()) {
      // Tried again at the next round; the queue waits meanwhile.
      logger_->error("slurm executor: {}", submitted.status().message());
      break;
    }
    logger_->info("slurm executor: submitted batch job {} ({} queued job(s))", *submitted,
                  demand->queued_simulations);
  }
}

}  // namespace seep::service
