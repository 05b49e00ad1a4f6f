// JobRunner::RunCalibration: a calibration job from its stored seep.v1.Calibration to its records.
//
// No checkpoints: a calibration is a handful of steady solves per target (seconds), so a job
// interrupted by a shutdown or a crash simply runs again from the start on the next seepd start
// (or after ResumeJob), and RecordCalibrations replaces whatever an earlier run stored. The
// records are stored before the job turns SUCCEEDED (as a simulation's series is), so a
// SUCCEEDED calibration job always has them.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>

#include "codec/calibration_codec.h"
#include "jobs/job_runner.h"
#include "jobs/wall_clock.h"
#include "seep/core/calibration/calibration.h"
#include "seep/v1/calibration.pb.h"

namespace seep::service {
namespace {

// The job's progress after a solve: each target owns 1/total of the bar, and each solve within a
// target covers half of what is left of its share (most targets converge in one to three solves,
// and the bar never goes back). step = solves so far over the whole job.
JobProgress CalibrationJobProgress(const core::CalibrationProgress& p, std::uint64_t solves) {
  const double total = static_cast<double>(std::max<std::size_t>(p.target_count, 1));
  const double within = 1.0 - std::pow(0.5, p.iteration);
  return JobProgress::At(solves, 0.0, (static_cast<double>(p.target_index) + within) / total, 0.0);
}

// The job result: the sweep at a glance, per target under "<name>[i]".
std::vector<std::pair<std::string, double>> CalibrationJobMetrics(
    const std::vector<core::CalibrationRecord>& records) {
  std::vector<std::pair<std::string, double>> m;
  m.emplace_back("target_count", static_cast<double>(records.size()));
  double worst = 0.0;
  for (const core::CalibrationRecord& r : records) {
    const std::size_t i = r.target_index;
    m.emplace_back(fmt::format("target_permeability_m2[{}]", i), r.target_permeability_m2);
    m.emplace_back(fmt::format("residual_aperture_m[{}]", i), r.residual_aperture_m);
    m.emplace_back(fmt::format("permeability_m2[{}]", i), r.permeability_m2);
    m.emplace_back(fmt::format("relative_error[{}]", i), r.relative_error);
    m.emplace_back(fmt::format("iterations[{}]", i), r.iterations);
    m.emplace_back(fmt::format("first_guess_relative_error[{}]", i), r.first_guess_relative_error);
    worst = std::max(worst, r.relative_error);
  }
  m.emplace_back("max_relative_error", worst);
  if (!records.empty()) {
    const core::CalibrationPackingStats& p = records.front().packing;
    m.emplace_back("particle_count", static_cast<double>(p.particle_count));
    m.emplace_back("pipe_count", static_cast<double>(p.pipe_count));
    m.emplace_back("porosity_2d", p.porosity_2d);
    m.emplace_back("mean_radius_m", p.mean_radius_m);
    m.emplace_back("coordination_number", p.coordination_number);
  }
  std::sort(m.begin(), m.end());
  return m;
}

}  // namespace

void JobRunner::RunCalibration(const JobRecord& job, Running& running) {
  const std::shared_ptr<spdlog::logger>& log = running.log;
  std::vector<core::CalibrationRecord> records;
  v1::Calibration calibration;
  const core::Status outcome = CatchAll([&]() -> core::Status {
    if (store_ == nullptr) {
      // The coordinator hands remote workers simulations only (WorkerService.ClaimJob).
      return core::FailedPrecondition(
          "calibration jobs run on seepd's own workers (--workers >= 1), not on a remote worker");
    }
    if (!calibration.ParseFromString(job.scene)) {
      return core::DataLoss("stored calibration bytes do not parse as seep.v1.Calibration");
    }
    auto spec = CalibrationFromProto(calibration);
    if (!spec.ok()) return spec.status();
    std::uint64_t solves = 0;
    core::CalibrationControl control;
    control.stop = running.stop.get_token();
    control.logger = log;
    control.on_progress = [&](const core::CalibrationProgress& p) {
      PublishProgress(job.id, running, CalibrationJobProgress(p, ++solves));
    };
    auto calibrated = core::CalibrateResidualAperture(*spec, control);
    if (!calibrated.ok()) return calibrated.status();
    records = std::move(*calibrated);
    return core::Status::Ok();
  });

  Ending ending;
  ending.kind = "calibration ";
  ending.keep_state = [](bool) { return true; };  // nothing to keep: a calibration reruns
  ending.interrupted = [&](double wall_s) {
    log->info("calibration interrupted by shutdown after {:.3f} s; it runs again on restart",
              wall_s);
    AddEvent(job.id, running, "INTERRUPTED",
             "shutdown during a calibration (no checkpoints: reruns)");
  };
  ending.succeed = [&](double wall_s) -> Status {
    const std::vector<std::pair<std::string, double>> metrics = CalibrationJobMetrics(records);
    SEEP_RETURN_IF_ERROR(CheckFiniteMetrics(metrics, "calibration result"));
    const std::string setup_sha = CalibrationSetupSha256(calibration);
    const std::int64_t now_ms = NowMs();
    std::vector<std::string> tags(calibration.tags().begin(), calibration.tags().end());
    std::sort(tags.begin(), tags.end());
    std::vector<StoredCalibration> rows;
    rows.reserve(records.size());
    for (const core::CalibrationRecord& r : records) {
      rows.push_back({0, job.id, r, 0.0, setup_sha, options_.build_id, now_ms, tags});
      rows.back().tolerance =
          calibration.tolerance() == 0.0 ? kDefaultCalibrationTolerance : calibration.tolerance();
    }
    std::uint64_t solves = 0;
    for (const core::CalibrationRecord& r : records)
      solves += static_cast<std::uint64_t>(r.iterations);
    if (auto s =
            ledger_.UpdateProgress(job.id, running.epoch, JobProgress::At(solves, 0.0, 1.0, 0.0));
        !s.ok()) {
      log->warn("final progress not stored: {}", s.ToString());
    }
    const auto write_result = [&]() -> Status {
      SEEP_RETURN_IF_ERROR(store_->RecordCalibrations(job.id, running.epoch, rows, tags));
      return ledger_.Finish(job.id, running.epoch, JobState::kSucceeded, "", "", metrics, wall_s);
    };
    SEEP_RETURN_IF_ERROR(RetryFinalWrite(running, "calibration result", true, write_result));
    log->info("calibration succeeded in {:.3f} s: {} target(s), {} permeameter solves", wall_s,
              records.size(), solves);
    return Status::Ok();
  };
  Conclude(job, running, outcome, ending);
}

}  // namespace seep::service
