#include "jobs/job_runner.h"

#include <fmt/format.h>

#include <chrono>
#include <exception>

#include "codec/scene_codec.h"
#include "codec/simulation_state_codec.h"
#include "jobs/wall_clock.h"
#include "seep/core/run/simulation.h"
#include "seep/core/threads.h"
#include "seep/v1/scene.pb.h"
#include "store/sha256.h"

namespace seep::service {
JobRunner::JobRunner(JobStore& store, JobHub& hub, JobRunnerOptions options,
                     std::shared_ptr<spdlog::logger> logger)
    : store_(store), hub_(hub), options_(std::move(options)), logger_(std::move(logger)) {}

JobRunner::~JobRunner() { Stop(); }

void JobRunner::Start() {
  for (int i = 0; i < options_.workers; ++i) {
    workers_.emplace_back([this](const std::stop_token& stop) { WorkerLoop(stop); });
  }
  heartbeat_ = std::jthread([this](const std::stop_token& stop) { HeartbeatLoop(stop); });
}

void JobRunner::Stop() {
  for (auto& w : workers_) w.request_stop();
  wake_.notify_all();
  workers_.clear();  // joins
  if (heartbeat_.joinable()) {
    heartbeat_.request_stop();
    heartbeat_wake_.notify_all();
    heartbeat_.join();
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
  const auto expires = NowMs() + options_.lease_duration.count();
  auto renewed = store_.Heartbeat(id, running.epoch, expires);
  if (!renewed.ok()) {
    if (renewed.status().code() == core::StatusCode::kAborted) {
      {
        std::lock_guard lock(mutex_);
        const auto it = running_.find(id);
        if (it == running_.end() || it->second.get() != &running) return;  // finished meanwhile
      }
      logger_->warn("job {}: lease lost ({}); stopping it", id, renewed.status().ToString());
      running.lease_lost = true;
      running.stop.request_stop();
    } else {
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
    for (auto& [id, running] : jobs) {
      if (stop.stop_requested()) break;
      Renew(id, *running);
    }
  }
}

void JobRunner::Wake() {
  {
    std::lock_guard lock(mutex_);
    ++wake_count_;
  }
  wake_.notify_one();
}

void JobRunner::WorkerLoop(const std::stop_token& stop) {
  // Per worker thread: the jobs it runs use this many threads, so that the workers together do
  // not ask for more cores than there are (oversubscribed barriers cost up to 100x).
  core::SetCoreThreadsForThisThread(options_.threads_per_job > 0
                                        ? options_.threads_per_job
                                        : core::CoreThreadsPerJob(options_.workers));
  while (!stop.stop_requested()) {
    std::uint64_t seen;
    {
      std::lock_guard lock(mutex_);
      seen = wake_count_;
    }
    auto claimed =
        store_.ClaimNextQueued(options_.lease_owner, NowMs(), options_.lease_duration.count());
    if (!claimed.ok()) {
      logger_->error("claiming a job failed: {}", claimed.status().ToString());
    } else if (claimed->has_value()) {
      RunJob(**claimed, stop);
      continue;
    }
    // Idle: sleep until woken, or poll now and then in case a wake-up was missed.
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, stop, std::chrono::seconds(1), [&] { return wake_count_ != seen; });
  }
}

void JobRunner::RunJob(const JobRecord& job, const std::stop_token& shutdown) {
  auto log = logger_->clone("job-" + job.id);
  auto running = std::make_shared<Running>();
  running->epoch = job.lease_epoch;
  {
    std::lock_guard lock(mutex_);
    running_[job.id] = running;
  }
  // Shutdown stops this job too, but is told apart from a cancel by the flags below.
  std::stop_callback on_shutdown(shutdown, [&running] { running->stop.request_stop(); });
  // A cancel stored between the claim and the registration above is seen here.
  Renew(job.id, *running);
  hub_.Publish(job.id, job.progress);
  const auto wall_start = std::chrono::steady_clock::now();
  log->info("started '{}' (attempt {}, lease epoch {})", job.name, job.attempt, job.lease_epoch);
  AddEvent(job.id, "CLAIMED",
           fmt::format("attempt {} by {} (lease epoch {})", job.attempt, options_.lease_owner,
                       job.lease_epoch));

  if (job.kind == JobKind::kCalibration) {
    RunCalibration(job, *running, wall_start, log);
    hub_.Finished(job.id);
    return;
  }

  CheckpointKeeper keeper(store_, options_.checkpoints, job, options_.build_id, log);
  std::optional<core::Simulation> sim;
  core::Status outcome = core::Internal("job did not run");
  std::uint64_t resumed_from = 0;
  try {
    v1::Scene scene_pb;
    if (!scene_pb.ParseFromString(job.scene)) {
      outcome = core::DataLoss("stored scene bytes do not parse as seep.v1.Scene");
    } else if (auto spec = SceneFromProto(scene_pb); !spec.ok()) {
      outcome = spec.status();
    } else if (auto created = core::Simulation::Create(*spec, log); !created.ok()) {
      outcome = created.status();
    } else {
      sim.emplace(std::move(*created));
      if (keeper.enabled()) resumed_from = keeper.RestoreNewest(*sim).value_or(0);
      keeper.StartClock();
      auto last_store_write = std::chrono::steady_clock::now();
      core::RunControl control;
      control.stop = running->stop.get_token();
      control.logger = log;
      control.on_progress = [&](const core::RunProgress& p) {
        const auto now = std::chrono::steady_clock::now();
        const double elapsed = std::chrono::duration<double>(now - wall_start).count();
        // The ETA counts only the part run in this attempt.
        const double start_fraction =
            static_cast<double>(resumed_from) / static_cast<double>(sim->total_steps());
        const double done_here = p.fraction_done - start_fraction;
        JobProgress progress =
            JobProgress::At(p.step, p.time_s, p.fraction_done,
                            done_here > 0.0 ? elapsed * (1.0 - p.fraction_done) / done_here : 0.0);
        const core::TimeSeries& series = sim->series();
        if (const std::size_t rows = series.rows(); rows > 0) {
          const std::size_t width = series.columns.size();
          for (std::size_t c = 1; c < width; ++c) {  // column 0 is time_s, already in progress
            progress.latest.emplace_back(series.columns[c], series.values[(rows - 1) * width + c]);
          }
        }
        hub_.Publish(job.id, progress);
        if (now - last_store_write >= options_.store_progress_interval) {
          last_store_write = now;
          if (auto s = store_.UpdateProgress(job.id, running->epoch, progress); !s.ok()) {
            if (s.code() == core::StatusCode::kAborted) {
              log->warn("lease lost ({}); stopping", s.ToString());
              running->lease_lost = true;
              running->stop.request_stop();
            } else {
              log->warn("progress not stored: {}", s.ToString());
            }
          }
        }
      };
      control.at_step_end = [&](const core::Simulation& at) {
        if (auto s = keeper.MaybeWrite(at); s.code() == core::StatusCode::kAborted) {
          log->warn("lease lost ({}); stopping", s.ToString());
          running->lease_lost = true;
          running->stop.request_stop();
        }
      };
      outcome = sim->Run(control);
    }
  } catch (const std::exception& e) {
    outcome = core::Internal(fmt::format("unexpected exception: {}", e.what()));
  }
  {
    std::lock_guard lock(mutex_);
    running_.erase(job.id);
  }
  Finish(job, *running, outcome, sim ? &*sim : nullptr, keeper, wall_start, log);
  hub_.Finished(job.id);
}

void JobRunner::Finish(const JobRecord& job, Running& running, const core::Status& outcome,
                       const core::Simulation* sim, CheckpointKeeper& keeper,
                       std::chrono::steady_clock::time_point wall_start,
                       const std::shared_ptr<spdlog::logger>& log) {
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const bool stopped =
      outcome.code() == core::StatusCode::kCancelled && running.stop.stop_requested();
  if (stopped && running.lease_lost) {
    // Another claim owns the job now: write nothing.
    log->warn("stopped after losing its lease; nothing recorded by this worker");
    return;
  }
  // A stopped run sits at a step boundary: keep its state so that it continues from here.
  if (stopped && sim != nullptr && keeper.Write(*sim).code() == core::StatusCode::kAborted) {
    log->warn("lease lost while writing the last checkpoint; nothing recorded");
    return;
  }
  // Where the run ended, for every outcome (the periodic progress write may be a second old).
  if (sim != nullptr && !(outcome.ok() && sim->finished())) {
    const double fraction =
        static_cast<double>(sim->step()) / static_cast<double>(sim->total_steps());
    if (auto s = store_.UpdateProgress(job.id, running.epoch,
                                       JobProgress::At(sim->step(), sim->time_s(), fraction, 0.0));
        !s.ok()) {
      log->warn("last progress not stored: {}", s.ToString());
    }
  }
  Status stored;
  if (stopped && running.cancel) {
    stored = store_.Finish(job.id, running.epoch, JobState::kCancelled, "CANCELLED",
                           outcome.message(), {}, wall_s, NowMs());
    log->info("cancelled after {:.3f} s: {}", wall_s, outcome.message());
  } else if (stopped) {
    // Shutdown, not a user's cancel: leave the job RUNNING so the next start queues it again.
    log->info("interrupted by shutdown after {:.3f} s at step {}; it continues on restart", wall_s,
              sim != nullptr ? sim->step() : 0);
    AddEvent(job.id, "INTERRUPTED",
             fmt::format("shutdown at step {}", sim != nullptr ? sim->step() : 0));
    return;
  } else if (outcome.ok() && sim != nullptr) {
    const core::RunReport report = sim->Report();
    const std::string state_sha = HexSha256(SerializeSimulationState(sim->TakeSnapshot()));
    (void)keeper.Write(*sim);  // the final state, for exports and later jobs
    if (auto s = store_.UpdateProgress(job.id, running.epoch,
                                       JobProgress::At(report.steps, report.time_s, 1.0, 0.0));
        !s.ok()) {
      log->warn("final progress not stored: {}", s.ToString());
    }
    stored = store_.StoreResultSeries(job.id, running.epoch, report.series.columns,
                                      report.series.values, state_sha);
    if (stored.ok()) {
      stored = store_.Finish(job.id, running.epoch, JobState::kSucceeded, "", "", report.metrics,
                             wall_s, NowMs());
    }
    log->info("succeeded in {:.3f} s after {} steps ({} checkpoints, {:.3f} s writing them)",
              wall_s, report.steps, keeper.written(), keeper.seconds_writing());
  } else {
    stored =
        store_.Finish(job.id, running.epoch, JobState::kFailed,
                      core::StatusCodeName(outcome.code()), outcome.message(), {}, wall_s, NowMs());
    log->warn("failed: {}", outcome.ToString());
  }
  if (!stored.ok()) log->error("could not record the outcome: {}", stored.ToString());
}

void JobRunner::AddEvent(const std::string& id, const std::string& kind,
                         const std::string& message) {
  if (auto s = store_.AddEvent(id, NowMs(), kind, message); !s.ok()) {
    logger_->warn("job {}: event not stored: {}", id, s.ToString());
  }
}

}  // namespace seep::service
