// Stages on the hydraulic-fracturing sample (a few seconds each in Release, minutes under the
// sanitizers: label `physics`, the Release suite only): a confine / inject / shut-in protocol,
// and one prepared sample forked into three injection rates.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "coupled_scenes.h"

namespace seep::core {
namespace {

using effects_test::HydrofracScene;
using effects_test::Metric;
using effects_test::MustCreate;
using effects_test::MustRun;
using effects_test::Stage;

// Hydraulic fracturing as a protocol: confine with the well shut in until the servos hold, inject
// until the well pressure is 20 % past its peak, shut in for 2 ms. The fluid injected is the
// rate times the injection stage's duration (the rate switched on and off exactly at the stage
// boundaries), and the books close.
TEST(Stages, HydraulicFracturingConfineInjectShutIn) {
  constexpr double kRate = 2e-4;
  SceneSpec s = HydrofracScene(1e5, 1e5);
  s.solver.end_time_s = 0.0;
  for (EffectSpec& e : s.effects) {
    if (auto* injection = std::get_if<InjectionEffectSpec>(&e)) injection->rate_m2_s = 0.0;
  }
  s.stages.push_back(Stage("confine", {ServoHeldEnd{0.05, 5e-4}}, 0.02));
  StageSpec inject = Stage("inject", {WellPressurePastPeakEnd{0.2}, BreakthroughEnd{}}, 0.05);
  inject.injection_rate_m2_s = kRate;
  s.stages.push_back(inject);
  StageSpec shut_in = Stage("shut-in", {DurationEnd{2e-3}});
  shut_in.injection_rate_m2_s = 0.0;
  s.stages.push_back(shut_in);
  Simulation sim = MustCreate(s);
  MustRun(sim);
  const RunReport r = sim.Report();
  std::printf("HF stages: confine %.4g s, inject %.4g s (ended by %g), breakdown %.4g Pa\n",
              Metric(r, "stage1_duration_s"), Metric(r, "stage2_duration_s"),
              Metric(r, "stage2_ended_by"), Metric(r, "breakdown_pressure_pa"));
  EXPECT_EQ(Metric(r, "stage1_ended_by"), 0.0);
  EXPECT_EQ(Metric(r, "stage1_fluid_injected_m2"), 0.0);
  EXPECT_GE(Metric(r, "stage2_ended_by"), 0.0);  // by a condition, not the max duration
  const double injected = Metric(r, "fluid_injected_m2");
  EXPECT_NEAR(injected, kRate * Metric(r, "stage2_duration_s"), 1e-12 * injected);
  EXPECT_EQ(injected, Metric(r, "stage2_fluid_injected_m2"));
  EXPECT_GT(Metric(r, "stage2_bonds_broken"), 0.0);
  EXPECT_LE(Metric(r, "fluid_balance_error"), 1e-10);
}

// One prepared sample feeds many tests: a run that only confines the hydraulic-fracturing sample
// (stage "confine") is snapshotted at its end, and three runs whose scenes add an injection stage
// at 1e-4, 2e-4 and 4e-4 m^2/s continue from that snapshot (what a fork does: the same scene up to
// the stages after the snapshot's current one). They start from the confined state (no step is
// repeated) and break down in the order of their rates: the faster the well is pressurised, the
// less the fluid soaks into the rock around it before the bonds fail.
TEST(Stages, ForksFromAPreparedSampleBreakDownInTheOrderOfTheirRates) {
  SceneSpec prepare = HydrofracScene(1e5, 1e5);
  prepare.solver.end_time_s = 0.0;
  for (EffectSpec& e : prepare.effects) {
    if (auto* injection = std::get_if<InjectionEffectSpec>(&e)) injection->rate_m2_s = 0.0;
  }
  prepare.stages.push_back(Stage("confine", {ServoHeldEnd{0.05, 5e-4}}, 0.02));
  Simulation sample = MustCreate(prepare);
  MustRun(sample);
  const SimulationSnapshot prepared = sample.TakeSnapshot();
  ASSERT_TRUE(prepared.stages.has_value());
  ASSERT_EQ(prepared.stages->index, 1u);  // the confinement ended
  std::vector<double> breakdown;
  for (const double rate : {1e-4, 2e-4, 4e-4}) {
    SceneSpec fork = prepare;
    StageSpec inject = Stage("inject", {WellPressurePastPeakEnd{0.2}, BreakthroughEnd{}}, 0.1);
    inject.injection_rate_m2_s = rate;
    fork.stages.push_back(inject);
    Simulation run = MustCreate(fork);
    const Status restored = run.Restore(prepared);
    ASSERT_TRUE(restored.ok()) << restored.message();
    MustRun(run);
    const RunReport r = run.Report();
    // Continued, not repeated: the confinement's metrics are the prepared run's.
    EXPECT_EQ(Metric(r, "stage1_duration_s"), Metric(sample.Report(), "stage1_duration_s"));
    EXPECT_GE(Metric(r, "stage2_ended_by"), 0.0);
    breakdown.push_back(Metric(r, "breakdown_pressure_pa"));
    std::printf("fork at %.3g m^2/s: breakdown %.5g Pa after %.4g s of injection\n", rate,
                breakdown.back(), Metric(r, "stage2_duration_s"));
  }
  EXPECT_LT(breakdown[0], breakdown[1]);
  EXPECT_LT(breakdown[1], breakdown[2]);
}

}  // namespace
}  // namespace seep::core
