// The reversal guard (core/run/reversal_guard.h) on the bonded sample it was built for:
// hydraulic_fracturing's lattice, whose disks are held by six contacts and bonds, has its fastest
// mode at velocity Verlet's limit somewhere between dt_safety 0.6 and 0.65 of the one-contact step.
// Past it the mode grows until bonds break and then stays at the limit inside the energy guard's
// budget (at 0.7, 352 bonds broke in 600 steps with the kinetic energy at 0.03-0.12 of it). The
// run must end FAILED before its bonds go, and a resumed run at the same step.
#include <gtest/gtest.h>

#include <cstdint>
#include <stop_token>
#include <string>

#include "codec/scene_codec.h"
#include "codec/simulation_state_codec.h"
#include "example_runs.h"
#include "seep/core/run/simulation.h"
#include "test_support.h"

namespace seep::service {
namespace {

core::SceneSpec FracturingAt(double dt_safety) {
  v1::Scene proto = testing::ExampleScene("hydraulic_fracturing.textproto");
  for (v1::Effect& effect : *proto.mutable_effects()) {
    if (effect.has_contacts()) effect.mutable_contacts()->set_dt_safety(dt_safety);
  }
  auto scene = SceneFromProto(proto);
  EXPECT_TRUE(scene.ok()) << scene.status().message();
  return scene.ok() ? *scene : core::SceneSpec{};
}

struct Ended {
  core::Status status;
  std::uint64_t step = 0;
  double bonds_broken = -1.0;
};

// Runs `sim` until it fails or reaches step `last` (then it is cancelled).
Ended RunTo(core::Simulation& sim, std::uint64_t last) {
  std::stop_source stop;
  core::RunControl control;
  control.stop = stop.get_token();
  control.at_step_end = [&](const core::Simulation& at) {
    if (at.step() >= last) stop.request_stop();
  };
  Ended ended;
  ended.status = sim.Run(control);
  ended.step = sim.step();
  for (const auto& [name, value] : sim.Report().metrics) {
    if (name == "bonds_broken") ended.bonds_broken = value;
  }
  return ended;
}

TEST(StabilityGuards, ABondedSampleWithItsFastestModeAtVerletsLimitEndsFailedBeforeItsBondsBreak) {
  auto unstable = core::Simulation::Create(FracturingAt(0.7));
  ASSERT_TRUE(unstable.ok()) << unstable.status().message();
  const Ended failed = RunTo(*unstable, 600);
  ASSERT_EQ(failed.status.code(), core::StatusCode::kFailedPrecondition)
      << failed.status.ToString();
  EXPECT_EQ(failed.step, 32u);
  for (const char* part : {"stability: at step 32 ", "the disks' velocities reverse",
                           "reversal ratio", "lower contacts.dt_safety (now 0.7)"}) {
    EXPECT_NE(failed.status.message().find(part), std::string::npos)
        << part << " not in: " << failed.status.message();
  }
  EXPECT_EQ(failed.bonds_broken, 0.0);

  // Below the limit the same sample runs on, its bonds whole.
  auto stable = core::Simulation::Create(FracturingAt(0.6));
  ASSERT_TRUE(stable.ok()) << stable.status().message();
  const Ended ran = RunTo(*stable, 600);
  EXPECT_EQ(ran.status.code(), core::StatusCode::kCancelled) << ran.status.ToString();
  EXPECT_EQ(ran.step, 600u);
  EXPECT_EQ(ran.bonds_broken, 0.0);
}

// The guard's count of checks in a row is in the checkpoint: stopped at step 28 (after one check
// past the limit, at 24) and resumed through the codec, the run fails at step 32 as the
// uninterrupted one does (with the count lost it would pass 32 and fail at 40).
TEST(StabilityGuards, AResumedRunFailsOnReversalAtTheUninterruptedRunsStep) {
  const core::SceneSpec scene = FracturingAt(0.7);
  auto first = core::Simulation::Create(scene);
  ASSERT_TRUE(first.ok()) << first.status().message();
  const Ended stopped = RunTo(*first, 28);
  ASSERT_EQ(stopped.status.code(), core::StatusCode::kCancelled) << stopped.status.ToString();
  auto snapshot = ParseSimulationState(SerializeSimulationState(first->TakeSnapshot()));
  ASSERT_TRUE(snapshot.ok()) << snapshot.status().ToString();
  ASSERT_TRUE(snapshot->mechanics && snapshot->mechanics->reversal_guard);
  EXPECT_EQ(snapshot->mechanics->reversal_guard->disk_checks, 1u);

  auto resumed = core::Simulation::Create(scene);
  ASSERT_TRUE(resumed.ok()) << resumed.status().message();
  ASSERT_TRUE(resumed->Restore(*snapshot).ok());
  const Ended failed = RunTo(*resumed, 600);
  EXPECT_EQ(failed.status.code(), core::StatusCode::kFailedPrecondition)
      << failed.status.ToString();
  EXPECT_EQ(failed.step, 32u);
}

}  // namespace
}  // namespace seep::service
