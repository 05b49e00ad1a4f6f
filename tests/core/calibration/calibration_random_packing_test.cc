// V6 (docs/physics.md §5) and its generalisation: calibrating a0 on the seeded random packing of
// the V06 scene test, with all pipes in compression (one cube-root correction is exact), over a
// sweep of targets, and with open gaps (a = a0 + m g) where the search must iterate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stop_token>
#include <string>
#include <vector>

#include "calibration_test_scenes.h"
#include "seep/core/calibration/calibration.h"
#include "seep/core/run/run_scene.h"

namespace seep::core {
namespace {

using calibration_test::CompressiveForces;
using calibration_test::RandomPackingSpec400;
using calibration_test::SceneContacts;

constexpr double kTolerance = 1e-6;

CalibrationSpec CompressedSpec(std::vector<double> targets) {
  CalibrationSpec spec = RandomPackingSpec400();
  spec.stress.contact_forces = CompressiveForces(SceneContacts(spec));
  spec.target_permeabilities_m2 = std::move(targets);
  spec.tolerance = kTolerance;
  return spec;
}

// A DEM-like stress state: overlapping contacts pushed apart with a normal stiffness
// (F = k_n overlap), the others (gap > 0) unloaded and open, a = a0 + m g with m = 0.5. Gaps go
// up to 20 um against a0 near 12 um, so open apertures are far from proportional to a0.
CalibrationSpec OpenGapSpec(std::vector<double> targets) {
  CalibrationSpec spec = RandomPackingSpec400();
  spec.scene.aperture.gap_multiplier = 0.5;
  const ContactList contacts = SceneContacts(spec);
  const double stiffness = 1e6;  // N/m per m: 10 um of overlap gives F = F0
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (contacts.gap[c] < 0.0) {
      spec.stress.contact_forces.push_back(
          {contacts.i[c], contacts.j[c], -stiffness * contacts.gap[c]});
    }
  }
  spec.target_permeabilities_m2 = std::move(targets);
  spec.tolerance = kTolerance;
  return spec;
}

CalibrationControl Recording(std::vector<CalibrationProgress>& progress) {
  CalibrationControl control;
  control.on_progress = [&progress](const CalibrationProgress& p) { progress.push_back(p); };
  return control;
}

TEST(CalibrationRandomPacking, V6_CompressionNeedsOneCorrection) {
  const double target = 1e-13;
  std::vector<CalibrationProgress> progress;
  const auto records = CalibrateResidualAperture(CompressedSpec({target}), Recording(progress));
  ASSERT_TRUE(records.ok()) << records.status().ToString();
  const CalibrationRecord& r = records->front();
  std::printf(
      "V6: first guess a0 = %.6e m (k error %.4f), calibrated a0 = %.6e m (k error %.2e) in %d "
      "solves\n",
      r.first_guess_residual_aperture_m, r.first_guess_relative_error, r.residual_aperture_m,
      r.relative_error, r.iterations);

  // Every aperture is a0 F0/(F + F0): k is proportional to a0^3 and the one cube-root correction
  // lands on the target to the solver's round-off, well inside the tolerance.
  EXPECT_EQ(r.stress.pipes_in_compression, r.packing.pipe_count);
  EXPECT_TRUE(r.stress.aperture_proportional_to_a0);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.relative_error, kTolerance);
  EXPECT_EQ(r.iterations, 2);
  EXPECT_EQ(r.corrections, 1);
  // docs/physics.md §1.3/§5 V6: the affine first guess is an upper bound that aperture disorder and
  // the random geometry pull the network below by 10-30%.
  EXPECT_LT(r.first_guess_permeability_m2, target);
  EXPECT_GE(r.first_guess_relative_error, 0.10);
  EXPECT_LE(r.first_guess_relative_error, 0.30);
  // The correction is the cube-root rescale of the first guess.
  EXPECT_NEAR(r.residual_aperture_m / r.first_guess_residual_aperture_m,
              std::cbrt(target / r.first_guess_permeability_m2), 1e-14);

  ASSERT_EQ(progress.size(), 2u);
  EXPECT_EQ(progress[0].iteration, 1);
  EXPECT_EQ(progress[0].relative_error, r.first_guess_relative_error);
  EXPECT_EQ(progress[1].residual_aperture_m, r.residual_aperture_m);
  EXPECT_EQ(progress[1].relative_error, r.relative_error);

  // The record's packing statistics (the packing of the V06 scene test).
  EXPECT_EQ(r.packing.particle_count, 400u);
  EXPECT_GT(r.packing.porosity_2d, 0.0);
  EXPECT_LT(r.packing.porosity_2d, 1.0);
  EXPECT_GT(r.packing.radius_std_dev_m, 0.0);
  EXPECT_LE(r.packing.min_radius_m, r.packing.mean_radius_m);
  EXPECT_GE(r.packing.max_radius_m, r.packing.mean_radius_m);
  EXPECT_DOUBLE_EQ(r.packing.coordination_number, 2.0 * r.packing.contact_count / 400.0);
  EXPECT_GE(r.stress.min_normal_force_n, 0.2 * calibration_test::kReferenceForce);
  EXPECT_LE(r.stress.max_normal_force_n, 1.2 * calibration_test::kReferenceForce);
}

TEST(CalibrationRandomPacking, SweepOfFiveTargetsScalesAsCubeRoot) {
  const std::vector<double> targets = {1e-14, 3e-14, 1e-13, 3e-13, 1e-12};
  const auto records = CalibrateResidualAperture(CompressedSpec(targets));
  ASSERT_TRUE(records.ok()) << records.status().ToString();
  ASSERT_EQ(records->size(), targets.size());
  const CalibrationRecord& base = records->front();
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const CalibrationRecord& r = (*records)[t];
    EXPECT_EQ(r.target_index, t);
    EXPECT_EQ(r.target_permeability_m2, targets[t]);
    EXPECT_TRUE(r.converged);
    EXPECT_LE(r.relative_error, kTolerance);
    EXPECT_EQ(r.iterations, 2);
    if (t > 0) {
      EXPECT_GT(r.residual_aperture_m, (*records)[t - 1].residual_aperture_m);
    }
    // k proportional to a0^3: each a0 is within tolerance/3 of its exact value, so the ratio of
    // two is within 2 tolerance/3 of cbrt(k_t / k_0).
    EXPECT_NEAR(r.residual_aperture_m / base.residual_aperture_m,
                std::cbrt(targets[t] / targets[0]), 2.0 * kTolerance / 3.0);
    // The first guess is equally good for every target (the estimate scales as a0^3 too).
    EXPECT_NEAR(r.first_guess_relative_error, base.first_guess_relative_error, 1e-12);
  }
}

TEST(CalibrationRandomPacking, OpenGapsConvergeByIteration) {
  const double target = 1e-13;
  std::vector<CalibrationProgress> progress;
  const auto records = CalibrateResidualAperture(OpenGapSpec({target}), Recording(progress));
  ASSERT_TRUE(records.ok()) << records.status().ToString();
  const CalibrationRecord& r = records->front();
  for (const CalibrationProgress& p : progress) {
    std::printf("open gaps: iteration %d a0 = %.9e m, k error %.3e\n", p.iteration,
                p.residual_aperture_m, p.relative_error);
  }
  EXPECT_GT(r.stress.pipes_open, 0u);
  EXPECT_GT(r.stress.pipes_in_compression, 0u);
  EXPECT_FALSE(r.stress.aperture_proportional_to_a0);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.relative_error, kTolerance);
  EXPECT_GT(r.iterations, 2);  // more than the one correction
  ASSERT_GE(progress.size(), 2u);
  // The cube-root step alone misses: the open apertures do not scale with a0.
  EXPECT_GT(progress[1].relative_error, kTolerance);
  EXPECT_EQ(progress.back().relative_error, r.relative_error);
}

TEST(CalibrationRandomPacking, DeterministicAndOrderIndependent) {
  const CalibrationSpec spec = OpenGapSpec({1e-13, 4e-13});
  const auto sweep = CalibrateResidualAperture(spec);
  ASSERT_TRUE(sweep.ok()) << sweep.status().ToString();
  auto calibrator = Calibrator::Create(spec);
  ASSERT_TRUE(calibrator.ok()) << calibrator.status().ToString();
  // Targets in reverse order on one calibrator: bit-identical to the sweep.
  for (std::size_t t : {1u, 0u}) {
    const auto r = calibrator->CalibrateTarget(t);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->residual_aperture_m, (*sweep)[t].residual_aperture_m);
    EXPECT_EQ(r->permeability_m2, (*sweep)[t].permeability_m2);
    EXPECT_EQ(r->iterations, (*sweep)[t].iterations);
    EXPECT_EQ(CalibrationMetrics(*r), CalibrationMetrics((*sweep)[t]));
  }
  // The network is built once: one symbolic analysis, a refactorization per solve.
  const LinearSystemStats& stats = calibrator->linear_system_stats();
  const std::int64_t solves = (*sweep)[0].iterations + (*sweep)[1].iterations;
  EXPECT_EQ(stats.analyses, 1);
  EXPECT_EQ(stats.factorizations, solves);
  EXPECT_EQ(stats.solves, solves);
}

TEST(CalibrationRandomPacking, RunningOutOfIterationsIsFailedPrecondition) {
  CalibrationSpec spec = OpenGapSpec({1e-13});
  spec.max_iterations = 2;  // the first guess and the cube-root step: not enough with open gaps
  const auto records = CalibrateResidualAperture(spec);
  ASSERT_EQ(records.status().code(), StatusCode::kFailedPrecondition)
      << records.status().ToString();
  const std::string message = records.status().message();
  EXPECT_EQ(message.rfind("calibration.target_permeabilities_m2[0]:", 0), 0u) << message;
  EXPECT_NE(message.find("best a0 = "), std::string::npos) << message;

  // The calibrator itself returns the best point, flagged.
  auto calibrator = Calibrator::Create(spec);
  ASSERT_TRUE(calibrator.ok()) << calibrator.status().ToString();
  const auto r = calibrator->CalibrateTarget(0);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_FALSE(r->converged);
  EXPECT_EQ(r->iterations, 2);
  EXPECT_GT(r->relative_error, kTolerance);
  EXPECT_LT(r->relative_error, r->first_guess_relative_error);
}

TEST(CalibrationRandomPacking, StopTokenCancels) {
  const CalibrationSpec spec = CompressedSpec({1e-13, 1e-12});
  std::stop_source stop;
  stop.request_stop();
  CalibrationControl control;
  control.stop = stop.get_token();
  EXPECT_EQ(CalibrateResidualAperture(spec, control).status().code(), StatusCode::kCancelled);

  // A stop requested during the first solve ends the run before the second.
  std::stop_source mid;
  int calls = 0;
  control.stop = mid.get_token();
  control.on_progress = [&](const CalibrationProgress&) {
    ++calls;
    mid.request_stop();
  };
  EXPECT_EQ(CalibrateResidualAperture(spec, control).status().code(), StatusCode::kCancelled);
  EXPECT_EQ(calls, 1);
}

TEST(CalibrationRandomPacking, RunSceneMeasuresTheTargetWithTheCalibratedAperture) {
  // Unloaded (no stress spec) with open gaps: the calibration's permeameter is then the scene
  // runner's, and the Darcy length it recomputes at each a0 is the one RunScene derives from the
  // scene's own apertures. So running the scene with the calibrated a0 measures the target.
  const double target = 2e-13;
  CalibrationSpec spec = RandomPackingSpec400();
  spec.scene.aperture.gap_multiplier = 0.5;
  spec.target_permeabilities_m2 = {target};
  spec.tolerance = kTolerance;
  const auto records = CalibrateResidualAperture(spec);
  ASSERT_TRUE(records.ok()) << records.status().ToString();
  const CalibrationRecord& r = records->front();
  EXPECT_EQ(r.stress.pipes_in_compression, 0u);
  EXPECT_GT(r.stress.pipes_open, 0u);
  EXPECT_GT(r.iterations, 2);
  std::printf("unloaded open gaps: a0 = %.9e m in %d solves, k error %.2e (first guess %.4f)\n",
              r.residual_aperture_m, r.iterations, r.relative_error, r.first_guess_relative_error);

  SceneSpec scene = spec.scene;
  scene.aperture.residual_aperture_m = r.residual_aperture_m;
  const auto run = RunScene(scene, {});
  ASSERT_TRUE(run.ok()) << run.status().ToString();
  double k = 0.0;
  double length = 0.0;
  for (const auto& [name, value] : run->metrics) {
    if (name == "permeability_m2") k = value;
    if (name == "sample_length_m") length = value;
  }
  // Same network, same solve: equal to round-off, and so within tolerance of the target.
  EXPECT_NEAR(k / r.permeability_m2, 1.0, 1e-12);
  EXPECT_NEAR(length / r.sample_length_m, 1.0, 1e-12);
  EXPECT_LE(std::abs(k - target) / target, kTolerance);
}

TEST(CalibrationLatticeCap, TargetAboveTheCapIsFailedPrecondition) {
  // Square lattice, a <= a_max everywhere: k can never exceed a_max^3 / (24 R).
  const double radius = 1e-3;
  const double cap = 1e-5;
  CalibrationSpec spec =
      calibration_test::PermeameterSpec(LatticePackingSpec{LatticeKind::kSquare, 10, 8, radius});
  spec.scene.aperture.max_aperture_m = cap;
  spec.target_permeabilities_m2 = {0.5 * cap * cap * cap / (24.0 * radius),
                                   2.0 * cap * cap * cap / (24.0 * radius)};
  const auto records = CalibrateResidualAperture(spec);
  ASSERT_EQ(records.status().code(), StatusCode::kFailedPrecondition)
      << records.status().ToString();
  EXPECT_EQ(records.status().message().rfind("calibration.target_permeabilities_m2[1]:", 0), 0u)
      << records.status().message();
  EXPECT_NE(records.status().message().find("max_aperture_m"), std::string::npos);

  // Below the cap the lattice is exact as before: a0 = (24 R k)^(1/3), one solve.
  auto calibrator = Calibrator::Create(spec);
  ASSERT_TRUE(calibrator.ok());
  const auto r = calibrator->CalibrateTarget(0);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->residual_aperture_m / (cap * std::cbrt(0.5)), 1.0, 1e-10);
  EXPECT_EQ(r->iterations, 1);
}

}  // namespace
}  // namespace seep::core
