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
}

void JobRunner::Stop() {
  for (auto& w : workers_) w.request_stop();
  wake_.notify_all();
  workers_.clear();  // joins
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
    auto claimed = store_.ClaimNextQueued(NowMs());
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

void JobRunner::RunJob(const JobRecord& job, const std::stop_token& stop) {
  auto log = logger_->clone("job-" + job.id);
  hub_.Publish(job.id, job.progress);
  const auto wall_start = std::chrono::steady_clock::now();
  log->info("started '{}'", job.name);

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
      control.stop = stop;
      control.logger = log;
      control.on_progress = [&](const core::RunProgress& p) {
        const auto now = std::chrono::steady_clock::now();
        const double elapsed = std::chrono::duration<double>(now - wall_start).count();
        JobProgress progress{p.step, p.time_s, p.fraction_done,
                             p.fraction_done > 0.0 ? elapsed * (1.0 / p.fraction_done - 1.0) : 0.0};
        hub_.Publish(job.id, progress);
        if (now - last_store_write >= options_.store_progress_interval) {
          last_store_write = now;
          if (auto s = store_.UpdateProgress(job.id, progress); !s.ok()) {
            log->warn("progress not stored: {}", s.ToString());
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

  if (!report.ok() && report.status().code() == core::StatusCode::kCancelled &&
      stop.stop_requested()) {
    // Shutdown, not a user's cancel: leave the job RUNNING so the next start queues it again.
    log->info("interrupted by shutdown after {:.3f} s; it will run again on restart", wall_s);
    hub_.Finished(job.id);
    return;
  }

  Status stored;
  if (report.ok()) {
    if (auto s = store_.UpdateProgress(job.id, {report->steps, report->time_s, 1.0, 0.0});
        !s.ok()) {
      log->warn("final progress not stored: {}", s.ToString());
    }
    stored = store_.Finish(job.id, JobState::kSucceeded, "", "", report->metrics, wall_s, NowMs());
    log->info("succeeded in {:.3f} s after {} steps", wall_s, report->steps);
  } else {
    const Status& s = report.status();
    stored = store_.Finish(job.id, JobState::kFailed, core::StatusCodeName(s.code()), s.message(),
                           {}, wall_s, NowMs());
    log->warn("failed: {}", s.ToString());
  }
  if (!stored.ok()) log->error("could not record the outcome: {}", stored.ToString());
  hub_.Finished(job.id);
}

}  // namespace seep::service
