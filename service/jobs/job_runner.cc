#include "jobs/job_runner.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <set>
#include <thread>

#include "codec/scene_codec.h"
#include "codec/simulation_state_codec.h"
#include "jobs/ending_slot.h"
#include "jobs/wall_clock.h"
#include "seep/core/run/simulation.h"
#include "seep/core/threads.h"
#include "seep/v1/scene.pb.h"
#include "store/sha256.h"

namespace seep::service {
namespace {
// Where --test-stall-job hangs a run and --test-crash-job (or --test-segfault-job) ends the
// process: this many steps
// into the claim.
constexpr std::uint64_t kTestStallStep = 1500;

// The store's form of where a run stands, its stage included.
JobProgress ProgressOf(const core::RunProgress& p, double eta_s) {
  JobProgress progress = JobProgress::At(p.step, p.time_s, p.fraction_done, eta_s);
  progress.stage_index = p.stage_index;
  progress.stage_count = p.stage_count;
  progress.stage_name = p.stage_name;
  return progress;
}

}  // namespace

JobRunner::JobRunner(JobLedger& ledger, JobStore* store, JobHub& hub, JobRunnerOptions options,
                     std::shared_ptr<spdlog::logger> logger)
    : ledger_(ledger),
      store_(store),
      hub_(hub),
      options_(std::move(options)),
      logger_(std::move(logger)),
      injected_final_write_failures_(options_.test_fail_final_writes) {}

JobRunner::~JobRunner() { Stop(); }

void JobRunner::Start() {
  idle_since_ = std::chrono::steady_clock::now();
  for (int i = 0; i < options_.workers; ++i) {
    workers_.emplace_back([this](const std::stop_token& stop) { WorkerLoop(stop); });
  }
  heartbeat_ = std::jthread([this](const std::stop_token& stop) { HeartbeatLoop(stop); });
  if (store_ != nullptr) {
    rescuer_ = std::jthread([this](const std::stop_token& stop) { RescueLoop(stop); });
  }
}

void JobRunner::Stop() {
  for (auto& w : workers_) w.request_stop();
  wake_.notify_all();
  workers_.clear();  // joins
  for (std::jthread* t : {&heartbeat_, &rescuer_}) {
    if (!t->joinable()) continue;
    t->request_stop();
    heartbeat_wake_.notify_all();
    t->join();
  }
}

void JobRunner::CancelRunning(const std::string& id) {
  std::lock_guard lock(mutex_);
  const auto it = running_.find(id);
  if (it == running_.end()) return;  // not here (yet): the heartbeat reads the stored request
  it->second->cancel = true;
  it->second->stop.request_stop();
}

void JobRunner::Renew(const std::string& id, Running& running) {
  auto renewed = ledger_.Heartbeat(id, running.epoch, options_.lease_duration);
  if (!renewed.ok()) {
    if (renewed.status().code() == core::StatusCode::kAborted) {
      std::lock_guard lock(mutex_);
      const auto it = running_.find(id);
      if (it == running_.end() || it->second.get() != &running) return;  // finished meanwhile
    }
    if (!running.StopIfLeaseLost(renewed.status())) {
      logger_->warn("job {}: heartbeat not stored: {}", id, renewed.status().ToString());
    }
  } else if (*renewed && !running.cancel) {
    running.cancel = true;
    running.stop.request_stop();
  }
}

void JobRunner::HeartbeatLoop(const std::stop_token& stop) {
  while (!stop.stop_requested()) {
    std::vector<std::pair<std::string, std::shared_ptr<Running>>> jobs;
    {
      std::unique_lock lock(mutex_);
      heartbeat_wake_.wait_for(lock, stop, options_.heartbeat_interval, [] { return false; });
      jobs.assign(running_.begin(), running_.end());
    }
    const auto now = std::chrono::steady_clock::now();
    for (auto& [id, running] : jobs) {
      if (stop.stop_requested()) break;
      if (options_.job_time_limit.count() > 0 &&
          now - running->wall_start > options_.job_time_limit && !running->time_limit_hit) {
        running->time_limit_hit = true;
        running->stop.request_stop();
      }
      if (!running->lease_lost) StoreHeldBackProgress(id, *running);
      // No progress since the last renewal: the worker may be hung, so let the lease run out
      // (in a supervised worker process, not during set-up: seepd watches that).
      const std::uint64_t ticks = running->ticks;
      if (ticks == running->renewed_ticks &&
          !(options_.renew_during_setup && running->setting_up)) {
        running->log->debug("no progress since the last lease renewal; not renewed");
        continue;
      }
      running->renewed_ticks = ticks;
      Renew(id, *running);
    }
  }
}

void JobRunner::RescueLoop(const std::stop_token& stop) {
  while (!stop.stop_requested()) {
    {
      std::unique_lock lock(mutex_);
      heartbeat_wake_.wait_for(lock, stop, options_.heartbeat_interval, [] { return false; });
    }
    if (!stop.stop_requested()) RescueExpired();
  }
}

void JobRunner::RescueExpired() {
  std::vector<CrashLoopFailure> crash_loops;
  auto expired = store_->RequeueExpired(NowMs(), options_.max_interruptions, &crash_loops);
  if (!expired.ok()) {
    logger_->error("rescuing jobs with expired leases failed: {}", expired.status().ToString());
    return;
  }
  std::set<std::string> failed;
  for (const CrashLoopFailure& f : crash_loops) {
    logger_->warn("job {} failed: {}", f.id, f.message);
    failed.insert(f.id);
  }
  for (const JobRecord& job : *expired) {
    std::shared_ptr<Running> hung;
    {
      std::lock_guard lock(mutex_);
      const auto it = running_.find(job.id);
      if (it != running_.end() && it->second->epoch == job.lease_epoch) {
        hung = it->second;
        running_.erase(it);
      }
    }
    if (hung) {
      hung->lease_lost = true;
      hung->stop.request_stop();
    }
    const std::string what = failed.contains(job.id) ? "failed (interrupted too often)"
                             : job.cancel_requested  ? "cancelled (a cancel was pending)"
                                                     : "queued to run again";
    const std::string message = fmt::format(
        "lease epoch {} of {} expired without progress ({} ms ago); {}", job.lease_epoch,
        job.lease_owner.value_or("?"), NowMs() - job.lease_expires_at_ms.value_or(0), what);
    logger_->warn("job {} rescued: {}", job.id, message);
    if (auto s = store_->AddEvent(job.id, NowMs(), "RESCUED", message); !s.ok()) {
      logger_->warn("job {}: event not stored: {}", job.id, s.ToString());
    }
    hub_.Finished(job.id);
  }
  if (!expired->empty()) wake_.notify_all();
}

void JobRunner::HogMemoryForTest(spdlog::logger& log) {
  log.warn("test hook --test-hog-memory-job: allocating until an allocation fails");
  constexpr std::size_t kBlock = std::size_t{64} << 20;
  std::vector<std::unique_ptr<char[]>> held;
  for (;;) {  // ends with std::bad_alloc, as a scene that outgrows its limit would
    held.push_back(std::make_unique<char[]>(kBlock));
    std::memset(held.back().get(), 1, kBlock);  // resident, not only reserved
  }
}

void JobRunner::StallForTest(Running& running) {
  running.log->warn("test hook --test-stall-job: this worker stops making progress");
  // Deaf to shutdown too, as a worker stuck inside a step would be: only the rescue wakes it.
  while (!running.lease_lost) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  running.log->warn("test hook --test-stall-job: the worker continues");
}

void JobRunner::Wake() {
  {
    std::lock_guard lock(mutex_);
    ++wake_count_;
  }
  // Every idle worker: a sweep queues many jobs at once, and a worker not woken would sleep
  // through them until its next poll.
  wake_.notify_all();
}

void JobRunner::WorkerLoop(const std::stop_token& stop) {
  // Per worker thread: the jobs it runs use this many threads, so that the workers together do
  // not ask for more cores than there are (oversubscribed barriers cost up to 100x).
  core::SetCoreThreadsForThisThread(options_.threads_per_job > 0
                                        ? options_.threads_per_job
                                        : core::CoreThreadsPerJob(options_.workers));
  // Destroyed before the worker ends: the last job's end is recorded first.
  EndingSlot endings;
  while (!stop.stop_requested()) {
    std::uint64_t seen;
    bool may_claim = true;
    {
      std::lock_guard lock(mutex_);
      seen = wake_count_;
      // The claim is counted before it is made, so that workers claiming at once cannot pass
      // max_jobs together.
      if (options_.max_jobs > 0 && claims_ >= options_.max_jobs) {
        may_claim = false;
      } else {
        ++claims_;
      }
    }
    if (may_claim) {
      auto claimed = ledger_.Claim(options_.lease_owner, options_.lease_duration);
      if (claimed.ok() && claimed->has_value()) {
        RunJob(std::move(**claimed), stop, endings);
        std::lock_guard lock(mutex_);
        idle_since_ = std::chrono::steady_clock::now();
        continue;
      }
      if (!claimed.ok()) logger_->error("claiming a job failed: {}", claimed.status().ToString());
      std::lock_guard lock(mutex_);
      --claims_;
    }
    // Idle: sleep until woken, or poll now and then in case a wake-up was missed.
    std::unique_lock lock(mutex_);
    if (WorkDoneLocked(std::chrono::steady_clock::now()) && !work_done_.exchange(true)) {
      const bool all_claimed = options_.max_jobs > 0 && claims_ >= options_.max_jobs;
      lock.unlock();
      if (all_claimed) {
        logger_->info("work done: {} job(s) claimed and ended (--max-jobs)", options_.max_jobs);
      } else {
        logger_->info(
            "work done: nothing to claim for {} s and no job running (--exit-when-idle-s)",
            std::chrono::duration<double>(options_.exit_when_idle).count());
      }
      if (options_.on_work_done) options_.on_work_done();
      lock.lock();
    }
    wake_.wait_for(lock, stop, options_.idle_poll, [&] { return wake_count_ != seen; });
  }
}

bool JobRunner::WorkDoneLocked(std::chrono::steady_clock::time_point now) const {
  if (!running_.empty()) return false;
  if (options_.max_jobs > 0 && claims_ >= options_.max_jobs) return true;
  return options_.exit_when_idle.count() > 0 && now - idle_since_ >= options_.exit_when_idle;
}

core::Status JobRunner::CatchAll(const std::function<core::Status()>& body) const {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return core::ResourceExhausted(fmt::format(
        "out of memory: an allocation failed{}; a smaller scene, or more memory for the job",
        options_.memory_limit_note.empty() ? "" : "; " + options_.memory_limit_note));
  } catch (const std::exception& e) {
    return core::Internal(fmt::format("unexpected exception: {}", e.what()));
  }
}

bool JobRunner::Running::StopIfLeaseLost(const core::Status& s) {
  if (s.code() != core::StatusCode::kAborted) return false;
  log->warn("lease lost ({}); stopping", s.ToString());
  lease_lost = true;
  stop.request_stop();
  return true;
}

bool JobRunner::Running::StopIfDiskFull(const core::Status& s) {
  if (s.code() != core::StatusCode::kResourceExhausted) return false;
  log->error("{}; stopping the job", s.message());
  disk_full = s;
  stop.request_stop();
  return true;
}

void JobRunner::RunJob(JobRecord job, const std::stop_token& shutdown, EndingSlot& endings) {
  auto running = std::make_shared<Running>();
  running->epoch = job.lease_epoch;
  running->log = logger_->clone("job-" + job.id);
  running->wall_start = std::chrono::steady_clock::now();
  running->last_store_write = running->wall_start;  // not shared yet
  {
    std::lock_guard lock(mutex_);
    running_[job.id] = running;
  }
  // Shutdown stops this job too, but is told apart from a cancel by the flags below.
  std::stop_callback on_shutdown(shutdown, [&running] { running->stop.request_stop(); });
  // A cancel stored between the claim and the registration above is seen at the first
  // heartbeat. (Not renewed here: from a remote worker that would open a lease stream for every
  // job, most of what a short job cost the coordinator.)
  hub_.RecordChanged(job.id);  // QUEUED -> RUNNING, for its followers
  hub_.Publish(job.id, job.progress);
  // (Its CLAIMED event was recorded with the claim, by the ledger.)
  running->log->info("started '{}' (attempt {}, lease epoch {})", job.name, job.attempt,
                     job.lease_epoch);
  if (job.kind == JobKind::kCalibration) {
    RunCalibration(job, *running);
    Ended(job.id, *running);
  } else {
    // The run is over; its end is recorded on the slot's thread while this worker claims the
    // next job (the job stays registered, its lease held, until Conclude).
    endings.Hand(RunSimulation(std::move(job), running));
  }
}

void JobRunner::Ended(const std::string& id, const Running& running) {
  Unregister(id, running);
  if (!running.lease_lost) hub_.Finished(id);  // else the rescuer did, or a new claim runs
  // A worker process that ends by itself checks whether its work is done when woken.
  if (options_.max_jobs > 0 || options_.exit_when_idle.count() > 0) Wake();
}

void JobRunner::Unregister(const std::string& id, const Running& running) {
  std::lock_guard lock(mutex_);
  const auto it = running_.find(id);
  if (it != running_.end() && it->second.get() == &running) running_.erase(it);
}

// What a simulation job's end needs once its run is over: it outlives RunSimulation, for the
// ending that a worker's EndingSlot records while the worker runs its next job.
struct JobRunner::SimulationRun {
  SimulationRun(JobRunner& runner, JobRecord claimed, std::shared_ptr<Running> run)
      : job(std::move(claimed)),
        running(std::move(run)),
        keeper(runner.ledger_, runner.options_.checkpoints, job, runner.options_.build_id,
               running->log) {}

  JobRecord job;  // before keeper, which refers to it
  std::shared_ptr<Running> running;
  CheckpointKeeper keeper;
  std::optional<core::Simulation> sim;
  core::Status outcome;
};

std::function<void()> JobRunner::RunSimulation(JobRecord claimed,
                                               const std::shared_ptr<Running>& registered) {
  auto run = std::make_shared<SimulationRun>(*this, std::move(claimed), registered);
  const JobRecord& job = run->job;
  Running& running = *run->running;
  CheckpointKeeper& keeper = run->keeper;
  std::optional<core::Simulation>& sim = run->sim;
  const std::shared_ptr<spdlog::logger>& log = running.log;
  run->outcome = CatchAll([&]() -> core::Status {
    v1::Scene scene_pb;
    if (!scene_pb.ParseFromString(job.scene)) {
      return core::DataLoss("stored scene bytes do not parse as seep.v1.Scene");
    }
    // Validated at submit; Simulation::Create validates it once more, for this build.
    auto spec = DecodeScene(scene_pb);
    if (!spec.ok()) return spec.status();
    auto created = core::Simulation::Create(*spec, log);
    if (!created.ok()) return created.status();
    sim.emplace(std::move(*created));
    running.setting_up = false;
    ++running.ticks;  // set-up done
    // A fork always continues from a checkpoint (its first one is its parent's, copied at
    // submit), even when this runner writes none; from the start it would not be that fork.
    // Any other job's first claim (lease epoch 1: epochs only grow, resumes included) has none to
    // look for: every checkpoint is written under a claim.
    std::optional<std::uint64_t> restored;
    if (job.parent_job_id || (keeper.enabled() && job.lease_epoch > 1)) {
      restored = keeper.RestoreNewest(*sim);
    }
    if (!restored && job.parent_job_id) {
      return core::FailedPrecondition(fmt::format(
          "a fork starts from its parent job {}'s checkpoint at step {} (copied as its first "
          "checkpoint), but none of its checkpoints can be used (see its CHECKPOINT_SKIPPED "
          "events); fork the parent again",
          *job.parent_job_id, job.parent_step));
    }
    const std::uint64_t resumed_from = restored.value_or(0);
    ++running.ticks;
    keeper.StartClock();
    // The ETA counts only the part run in this attempt.
    const double start_fraction = sim->Progress().fraction_done;
    core::RunControl control;
    control.stop = running.stop.get_token();
    control.logger = log;
    control.on_progress = [&](const core::RunProgress& p) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - running.wall_start)
              .count();
      const double done_here = p.fraction_done - start_fraction;
      JobProgress progress =
          ProgressOf(p, done_here > 0.0 ? elapsed * (1.0 - p.fraction_done) / done_here : 0.0);
      const std::vector<std::string>& columns = sim->series().columns;
      const std::vector<double>& latest = sim->latest_sample();
      for (std::size_t c = 1; c < latest.size() && c < columns.size(); ++c) {
        progress.latest.emplace_back(columns[c], latest[c]);  // column 0 is time_s, in progress
      }
      PublishProgress(job.id, running, progress);
    };
    const bool stall = !options_.test_stall_job.empty() && job.name == options_.test_stall_job &&
                       job.lease_epoch == 1;
    const bool crash = !options_.test_crash_job.empty() && job.name == options_.test_crash_job;
    const bool segfault =
        !options_.test_segfault_job.empty() && job.name == options_.test_segfault_job;
    const bool hog =
        !options_.test_hog_memory_job.empty() && job.name == options_.test_hog_memory_job;
    // Steps are counted into the shared metric in batches: an atomic add per step from every
    // worker would bounce one cache line between the cores at every step.
    constexpr std::uint64_t kStepsPerMetricUpdate = 64;
    std::uint64_t uncounted_steps = 0;
    control.at_step_end = [&](const core::Simulation& at) {
      if (stall && at.step() == resumed_from + kTestStallStep) StallForTest(running);
      if (crash && at.step() == resumed_from + kTestStallStep) {
        log->critical("test hook --test-crash-job: ending the process");
        std::_Exit(86);
      }
      if (segfault && at.step() == resumed_from + kTestStallStep) {
        log->critical("test hook --test-segfault-job: a segmentation fault");
        // The default action (a sanitizer's handler would turn it into an abort).
        std::signal(SIGSEGV, SIG_DFL);
        std::raise(SIGSEGV);
      }
      if (hog && at.step() == resumed_from + kTestStallStep) HogMemoryForTest(*log);
      if (options_.metrics != nullptr && ++uncounted_steps == kStepsPerMetricUpdate) {
        options_.metrics->AddSteps(uncounted_steps);
        uncounted_steps = 0;
      }
      if (running.lease_lost) return;  // stopping: another claim writes the checkpoints now
      ++running.ticks;
      const core::Status written = keeper.MaybeWrite(at);
      if (!running.StopIfLeaseLost(written)) running.StopIfDiskFull(written);
    };
    core::Status ran = sim->Run(control);
    if (options_.metrics != nullptr) options_.metrics->AddSteps(uncounted_steps);
    return ran;
  });
  return [this, run] { ConcludeSimulation(*run); };
}

void JobRunner::ConcludeSimulation(SimulationRun& run) {
  const JobRecord& job = run.job;
  Running& running = *run.running;
  CheckpointKeeper& keeper = run.keeper;
  std::optional<core::Simulation>& sim = run.sim;
  const core::Status& outcome = run.outcome;
  const std::shared_ptr<spdlog::logger>& log = running.log;
  Ending ending;
  ending.kind = "";
  ending.keep_state = [&](bool stopped) {
    // A stopped run sits at a step boundary: keep its state so that it continues from here
    // (unless a full disk stopped it: there is no room for it).
    if (stopped && running.disk_full.ok() && sim &&
        keeper.Write(*sim).code() == core::StatusCode::kAborted) {
      log->warn("lease lost while writing the last checkpoint; nothing recorded");
      return false;
    }
    // Where the run ended, for every outcome (the periodic progress write may be a second old).
    if (sim && !(outcome.ok() && sim->finished())) {
      if (auto s = ledger_.UpdateProgress(job.id, running.epoch, ProgressOf(sim->Progress(), 0.0));
          !s.ok()) {
        log->warn("last progress not stored: {}", s.ToString());
      }
    }
    return true;
  };
  ending.interrupted = [&](double wall_s) {
    const std::uint64_t step = sim ? sim->step() : 0;
    log->info("interrupted by shutdown after {:.3f} s at step {}; it continues on restart", wall_s,
              step);
    AddEvent(job.id, running, "INTERRUPTED", fmt::format("shutdown at step {}", step));
  };
  ending.succeed = [&](double wall_s) -> Status {
    core::RunReport report = sim->Report();
    SEEP_RETURN_IF_ERROR(CheckFiniteMetrics(report.metrics, "job result"));
    // Serialized once: the final checkpoint holds the very bytes the result's hash covers.
    const std::string state = SerializeSimulationState(sim->TakeSnapshot());
    // Done, in the last stage (its name stays for seep show).
    core::RunProgress done = sim->Progress();
    done.step = report.steps;
    done.time_s = report.time_s;
    done.fraction_done = 1.0;
    RunSuccess success;
    success.series_columns = std::move(report.series.columns);
    success.series_values = std::move(report.series.values);
    success.state_sha256 = HexSha256(state);
    success.final_progress = ProgressOf(done, 0.0);
    success.metrics = std::move(report.metrics);
    success.wall_time_s = wall_s;
    // The final state (for exports and later jobs) is kept with the success, in one record.
    const std::optional<FinalState> final_state = keeper.FinalStateOf(*sim, state);
    const auto start = std::chrono::steady_clock::now();
    FinalStateKept kept;
    SEEP_RETURN_IF_ERROR(RetryFinalWrite(running, "result", true, [&]() -> Status {
      SEEP_ASSIGN_OR_RETURN(kept, ledger_.RecordSuccess(job, running.epoch, final_state, success));
      return Status::Ok();
    }));
    if (final_state) {
      keeper.CountFinalState(
          *final_state, kept,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    log->info("succeeded in {:.3f} s after {} steps ({} checkpoints, {:.3f} s writing them)",
              wall_s, report.steps, keeper.written(), keeper.seconds_writing());
    return Status::Ok();
  };
  Conclude(job, running, outcome, ending);
  Ended(job.id, running);
}

void JobRunner::PublishProgress(const std::string& id, Running& running,
                                const JobProgress& progress) {
  if (running.lease_lost) return;  // the job is queued again or another claim runs it
  ++running.ticks;
  hub_.Publish(id, progress);
  {
    std::lock_guard lock(running.progress_mutex);
    const auto now = std::chrono::steady_clock::now();
    if (now - running.last_store_write < options_.store_progress_interval) {
      running.unstored_progress = progress;
      return;
    }
    running.last_store_write = now;
    running.unstored_progress.reset();
  }
  StoreProgress(id, running, progress);
}

void JobRunner::StoreHeldBackProgress(const std::string& id, Running& running) {
  std::optional<JobProgress> held_back;
  {
    std::lock_guard lock(running.progress_mutex);
    const auto now = std::chrono::steady_clock::now();
    if (!running.unstored_progress ||
        now - running.last_store_write < options_.store_progress_interval) {
      return;
    }
    running.last_store_write = now;
    held_back.swap(running.unstored_progress);
  }
  StoreProgress(id, running, *held_back);
}

void JobRunner::StoreProgress(const std::string& id, Running& running,
                              const JobProgress& progress) {
  if (auto s = ledger_.UpdateProgress(id, running.epoch, progress);
      !s.ok() && !running.StopIfLeaseLost(s)) {
    running.log->warn("progress not stored: {}", s.ToString());
  }
}

void JobRunner::Conclude(const JobRecord& job, Running& running, const core::Status& outcome,
                         const Ending& ending) {
  Unregister(job.id, running);  // the heartbeat renews its lease no more
  const std::shared_ptr<spdlog::logger>& log = running.log;
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - running.wall_start).count();
  const bool stopped =
      outcome.code() == core::StatusCode::kCancelled && running.stop.stop_requested();
  if (stopped && running.lease_lost) {
    // Another claim owns the job now: write nothing.
    log->warn("stopped after losing its lease; nothing recorded by this worker");
    return;
  }
  if (!ending.keep_state(stopped)) return;
  Status stored;
  if (stopped && running.cancel) {
    stored = ledger_.Finish(job.id, running.epoch, JobState::kCancelled, "CANCELLED",
                            outcome.message(), {}, wall_s);
    log->info("{}cancelled after {:.3f} s: {}", ending.kind, wall_s, outcome.message());
  } else if (stopped && running.time_limit_hit) {
    const std::string message = fmt::format(
        "wall-time limit exceeded: ran {:.1f} s in this claim, the limit is {} s "
        "(--job-time-limit-s); `seep resume` continues it from its last checkpoint",
        wall_s, std::chrono::duration<double>(options_.job_time_limit).count());
    stored = ledger_.Finish(job.id, running.epoch, JobState::kFailed, "DEADLINE_EXCEEDED", message,
                            {}, wall_s);
    log->warn("{}failed: {}", ending.kind, message);
  } else if (stopped && !running.disk_full.ok()) {
    const std::string message = fmt::format(
        "{}; the job stopped there and keeps its newest checkpoint: free space on the data "
        "folder's disk (or lower --min-free-disk-mb), then `seep resume` continues it from that "
        "checkpoint",
        running.disk_full.message());
    stored = ledger_.Finish(job.id, running.epoch, JobState::kFailed, "RESOURCE_EXHAUSTED", message,
                            {}, wall_s);
    log->error("{}failed: {}", ending.kind, message);
  } else if (stopped) {
    // Shutdown, not a user's cancel: leave the job RUNNING so the next start queues it again,
    // its lease released (a clean stop is not an interruption without progress).
    ending.interrupted(wall_s);
    if (auto s = ledger_.ReleaseLease(job.id, running.epoch); !s.ok()) {
      log->warn("lease not released: {}", s.ToString());
    }
    return;
  } else if (outcome.ok()) {
    stored = ending.succeed(wall_s);
    if (!stored.ok() && stored.code() != core::StatusCode::kAborted) {
      // Never left RUNNING with a result that cannot be stored: FAILED, saying why.
      const std::string message =
          fmt::format("the result could not be recorded: {}", stored.message());
      log->error("{}failed: {}", ending.kind, message);
      const std::string code = core::StatusCodeName(stored.code());
      stored = RetryFinalWrite(running, "failure", false, [&] {
        return ledger_.Finish(job.id, running.epoch, JobState::kFailed, code, message, {}, wall_s);
      });
    }
  } else {
    stored = ledger_.Finish(job.id, running.epoch, JobState::kFailed,
                            core::StatusCodeName(outcome.code()), outcome.message(), {}, wall_s);
    log->warn("{}failed: {}", ending.kind, outcome.ToString());
  }
  if (!stored.ok()) {
    // Its lease is renewed no more: the rescuer queues it again once the lease expires.
    log->error("could not record the outcome: {}", stored.ToString());
  }
}

core::Status JobRunner::RetryFinalWrite(Running& running, const char* what, bool injectable,
                                        const std::function<core::Status()>& write) {
  const int attempts = std::max(1, options_.final_write_attempts);
  auto wait = options_.final_write_backoff;
  for (int attempt = 1;; ++attempt) {
    int injected = injectable ? injected_final_write_failures_.load() : 0;
    while (injected > 0 &&
           !injected_final_write_failures_.compare_exchange_weak(injected, injected - 1)) {
    }
    core::Status s =
        injected > 0 ? core::Unavailable("injected final-write failure (--test-fail-final-writes)")
                     : write();
    if (s.ok() || s.code() == core::StatusCode::kAborted ||
        s.code() == core::StatusCode::kInvalidArgument) {
      return s;
    }
    if (attempt >= attempts) {
      return {s.code(),
              fmt::format("{} not stored after {} tries: {}", what, attempts, s.message())};
    }
    running.log->warn("{} not stored (try {} of {}): {}; trying again in {} ms", what, attempt,
                      attempts, s.ToString(), wait.count());
    std::this_thread::sleep_for(wait);
    wait *= 2;
  }
}

void JobRunner::AddEvent(const std::string& id, const Running& running, const std::string& kind,
                         const std::string& message) {
  if (auto s = ledger_.AddEvent(id, running.epoch, kind, message); !s.ok()) {
    logger_->warn("job {}: event not stored: {}", id, s.ToString());
  }
}

}  // namespace seep::service
