#include "jobs/job_runner.h"

#include <fmt/format.h>

#include <chrono>
#include <exception>

#include "codec/scene_codec.h"
#include "seep/core/scene/run_scene.h"
#include "seep/v1/scene.pb.h"

namespace seep::service {
namespace {

std::int64_t NowMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

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

  core::Result<core::RunReport> report = core::Internal("job did not run");
  try {
    v1::Scene scene_pb;
    if (!scene_pb.ParseFromString(job.scene)) {
      report = core::DataLoss("stored scene bytes do not parse as seep.v1.Scene");
    } else if (auto spec = SceneFromProto(scene_pb); !spec.ok()) {
      report = spec.status();
    } else {
      auto last_store_write = std::chrono::steady_clock::now();
      core::RunControl control;
      control.stop = running->stop.get_token();
      control.logger = log;
      control.on_progress = [&](const core::RunProgress& p) {
        const auto now = std::chrono::steady_clock::now();
        const double elapsed = std::chrono::duration<double>(now - wall_start).count();
        JobProgress progress{p.step, p.time_s, p.fraction_done,
                             p.fraction_done > 0.0 ? elapsed * (1.0 / p.fraction_done - 1.0) : 0.0};
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
      report = core::RunScene(*spec, control);
    }
  } catch (const std::exception& e) {
    report = core::Internal(fmt::format("unexpected exception: {}", e.what()));
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  {
    std::lock_guard lock(mutex_);
    running_.erase(job.id);
  }

  const bool stopped = !report.ok() && report.status().code() == core::StatusCode::kCancelled &&
                       running->stop.stop_requested();
  Status stored;
  if (stopped && running->lease_lost) {
    // Another claim owns the job now: write nothing.
    log->warn("stopped after losing its lease; nothing recorded by this worker");
    hub_.Finished(job.id);
    return;
  } else if (stopped && running->cancel) {
    stored = store_.Finish(job.id, running->epoch, JobState::kCancelled, "CANCELLED",
                           report.status().message(), {}, wall_s, NowMs());
    log->info("cancelled after {:.3f} s: {}", wall_s, report.status().message());
  } else if (stopped) {
    // Shutdown, not a user's cancel: leave the job RUNNING so the next start queues it again.
    log->info("interrupted by shutdown after {:.3f} s; it will run again on restart", wall_s);
    hub_.Finished(job.id);
    return;
  } else if (report.ok()) {
    if (auto s = store_.UpdateProgress(job.id, running->epoch,
                                       {report->steps, report->time_s, 1.0, 0.0});
        !s.ok()) {
      log->warn("final progress not stored: {}", s.ToString());
    }
    stored = store_.Finish(job.id, running->epoch, JobState::kSucceeded, "", "", report->metrics,
                           wall_s, NowMs());
    log->info("succeeded in {:.3f} s after {} steps", wall_s, report->steps);
  } else {
    const Status& s = report.status();
    stored = store_.Finish(job.id, running->epoch, JobState::kFailed,
                           core::StatusCodeName(s.code()), s.message(), {}, wall_s, NowMs());
    log->warn("failed: {}", s.ToString());
  }
  if (!stored.ok()) log->error("could not record the outcome: {}", stored.ToString());
  hub_.Finished(job.id);
}

}  // namespace seep::service
