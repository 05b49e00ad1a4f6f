// Snapshot and restore: a run stopped at any step, snapshotted, and continued in a fresh
// Simulation of the same scene ends bit-identical to the uninterrupted run (what the job
// service's checkpoints rely on).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stop_token>

#include "scene_test_util.h"
#include "seep/core/run/simulation.h"
#include "seep/core/run/stepper.h"

namespace seep::core {
namespace {

SceneSpec TransientScene(SolverKind kind) {
  SceneSpec s = scene_test::RandomScene(11);
  s.solver.kind = kind;
  // About 60 explicit or 45 implicit steps.
  s.solver.dt_factor = kind == SolverKind::kExplicit ? 0.9 : 1.2;
  s.solver.end_time_s = 5e-6;
  s.solver.progress_every = 7;
  return s;
}

bool BitIdentical(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

SimulationSnapshot RunToEnd(Simulation& sim) {
  EXPECT_TRUE(sim.Run({}).ok());
  return sim.TakeSnapshot();
}

// Stops the run when it reaches `stop_at` steps and returns the snapshot taken there.
SimulationSnapshot RunUntil(Simulation& sim, std::uint64_t stop_at) {
  std::stop_source stop;
  RunControl control;
  control.stop = stop.get_token();
  control.at_step_end = [&](const Simulation& s) {
    if (s.step() == stop_at) stop.request_stop();
  };
  const Status status = sim.Run(control);
  EXPECT_EQ(status.code(), StatusCode::kCancelled) << status.ToString();
  EXPECT_EQ(sim.step(), stop_at);
  return sim.TakeSnapshot();
}

class SnapshotResume : public ::testing::TestWithParam<SolverKind> {};

TEST_P(SnapshotResume, ResumedRunIsBitIdenticalToTheUninterruptedOne) {
  const SceneSpec scene = TransientScene(GetParam());
  auto reference = Simulation::Create(scene);
  ASSERT_TRUE(reference.ok()) << reference.status().ToString();
  ASSERT_GT(reference->total_steps(), 20u);
  const SimulationSnapshot expected = RunToEnd(*reference);
  const RunReport expected_report = reference->Report();

  // Interrupt twice, each time continuing in a new Simulation built from the scene alone.
  const std::uint64_t cuts[] = {3, reference->total_steps() / 2};
  SimulationSnapshot carried;
  bool have_carried = false;
  for (const std::uint64_t cut : cuts) {
    auto sim = Simulation::Create(scene);
    ASSERT_TRUE(sim.ok());
    if (have_carried) {
      ASSERT_TRUE(sim->Restore(carried).ok());
    }
    carried = RunUntil(*sim, cut);
    have_carried = true;
  }
  auto last = Simulation::Create(scene);
  ASSERT_TRUE(last.ok());
  ASSERT_TRUE(last->Restore(carried).ok());
  const SimulationSnapshot resumed = RunToEnd(*last);

  EXPECT_EQ(resumed.step, expected.step);
  EXPECT_EQ(std::memcmp(&resumed.time_s, &expected.time_s, sizeof(double)), 0);
  EXPECT_TRUE(BitIdentical(resumed.pressure, expected.pressure));
  EXPECT_TRUE(BitIdentical(resumed.series.values, expected.series.values));
  EXPECT_EQ(std::memcmp(&resumed.worst_mass_balance_error, &expected.worst_mass_balance_error,
                        sizeof(double)),
            0);
  const RunReport report = last->Report();
  ASSERT_EQ(report.metrics.size(), expected_report.metrics.size());
  for (std::size_t i = 0; i < report.metrics.size(); ++i) {
    EXPECT_EQ(report.metrics[i].first, expected_report.metrics[i].first);
    EXPECT_EQ(
        std::memcmp(&report.metrics[i].second, &expected_report.metrics[i].second, sizeof(double)),
        0)
        << report.metrics[i].first;
  }
  // Samples at fixed steps: every 7th step, the last, and the initial state.
  const std::uint64_t n = expected.step;
  const std::size_t rows = 1 + n / 7 + (n % 7 != 0 ? 1 : 0);
  EXPECT_EQ(expected.series.rows(), rows);
}

INSTANTIATE_TEST_SUITE_P(Solvers, SnapshotResume,
                         ::testing::Values(SolverKind::kExplicit, SolverKind::kImplicit),
                         [](const auto& param_info) {
                           return param_info.param == SolverKind::kExplicit ? "Explicit"
                                                                            : "Implicit";
                         });

// progress_every = 1 on a run of thousands of steps: the series is decimated to at most
// kMaxSeriesRows rows (every other row dropped, the stride doubled), and a run resumed from a
// snapshot taken between two halvings keeps the very same rows.
TEST(SnapshotResume, SeriesStaysBoundedAndResumesWithTheSameRows) {
  SceneSpec scene = TransientScene(SolverKind::kExplicit);
  scene.solver.progress_every = 1;
  scene.solver.end_time_s = 5.5e-4;  // about 5300 steps
  auto reference = Simulation::Create(scene);
  ASSERT_TRUE(reference.ok()) << reference.status().ToString();
  const std::uint64_t total = reference->total_steps();
  ASSERT_GT(total, 4 * Stepper::kMaxSeriesRows);
  const SimulationSnapshot expected = RunToEnd(*reference);
  EXPECT_LE(expected.series.rows(), Stepper::kMaxSeriesRows);
  EXPECT_GT(expected.series.rows(), Stepper::kMaxSeriesRows / 2);
  EXPECT_EQ(reference->stepper().series_stride() % 4, 0u);  // halved at least twice
  // The newest sample is of the last step, whatever the series keeps.
  EXPECT_EQ(reference->latest_sample().front(), reference->time_s());

  // Cut at an odd step past the first halving: the stride is rebuilt from the step alone.
  auto first = Simulation::Create(scene);
  ASSERT_TRUE(first.ok());
  const SimulationSnapshot carried = RunUntil(*first, 2 * Stepper::kMaxSeriesRows + 3);
  auto last = Simulation::Create(scene);
  ASSERT_TRUE(last.ok());
  ASSERT_TRUE(last->Restore(carried).ok());
  EXPECT_EQ(last->stepper().series_stride(), first->stepper().series_stride());
  const SimulationSnapshot resumed = RunToEnd(*last);
  EXPECT_TRUE(BitIdentical(resumed.series.values, expected.series.values));
  EXPECT_TRUE(BitIdentical(resumed.pressure, expected.pressure));
}

TEST(SnapshotRestore, SnapshotOfAnotherSceneIsRefusedAndLeavesTheStateAlone) {
  auto small = Simulation::Create(TransientScene(SolverKind::kExplicit));
  ASSERT_TRUE(small.ok());
  SceneSpec other = TransientScene(SolverKind::kExplicit);
  std::get<RandomPackingSpec>(other.packing.source).seed = 12;
  auto sim = Simulation::Create(other);
  ASSERT_TRUE(sim.ok());
  SimulationSnapshot wrong = small->TakeSnapshot();
  if (wrong.pressure.size() == sim->network().flow.num_domains()) wrong.pressure.push_back(0.0);
  const auto before = sim->TakeSnapshot();
  const Status status = sim->Restore(wrong);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_NE(status.message().find("snapshot.pressure"), std::string::npos) << status.ToString();
  EXPECT_TRUE(BitIdentical(sim->TakeSnapshot().pressure, before.pressure));
  EXPECT_EQ(sim->step(), 0u);
}

TEST(SnapshotRestore, NonFinitePressureIsRefused) {
  auto sim = Simulation::Create(TransientScene(SolverKind::kImplicit));
  ASSERT_TRUE(sim.ok());
  SimulationSnapshot snap = sim->TakeSnapshot();
  snap.pressure[1] = std::numeric_limits<double>::quiet_NaN();
  const Status status = sim->Restore(snap);
  EXPECT_EQ(status.code(), StatusCode::kDataLoss);
  EXPECT_NE(status.message().find("snapshot.pressure[1]"), std::string::npos);
}

// A report is checked where it is measured: a metric that is not a number is named.
TEST(RunReport, AMetricThatIsNotFiniteIsNamed) {
  EXPECT_TRUE(CheckMetricsFinite({{"inflow_m2_per_s", 1e-6}, {"steps", 3}}).ok());
  const Status nan =
      CheckMetricsFinite({{"inflow_m2_per_s", 1e-6}, {"permeability_m2", std::nan("")}});
  EXPECT_EQ(nan.code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(nan.message(), "report: metric 'permeability_m2' is not a finite number (got nan)");
  EXPECT_EQ(CheckMetricsFinite({{"p_max", -std::numeric_limits<double>::infinity()}}).message(),
            "report: metric 'p_max' is not a finite number (got -inf)");
}

}  // namespace
}  // namespace seep::core
