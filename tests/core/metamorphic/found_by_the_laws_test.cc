// Scenes on which a law of scene_laws.h failed, kept as named tests (the bench found them; the
// seed reproduces the scene: seep_scene_laws_bench --seed N).
#include <gtest/gtest.h>

#include <algorithm>
#include <stop_token>

#include "scene_generator.h"
#include "scene_laws.h"
#include "seep/core/run/simulation.h"

namespace seep::core::metamorphic {
namespace {

// A sealed box with a servo lid, bonds and re-detection, stopped at step 42 of 43: the critical
// step a resumed run reported (metric dt_crit_s) was the one its re-bind measured on the
// detection's volumes, not the last flow update's (3.51580e-5 against 3.51657e-5 s). The
// checkpoint keeps it now (checkpoint fields 38 and 39).
TEST(FoundByTheLaws, ResumeReportsTheCriticalStepOfTheLastFlowUpdate) {
  const GeneratedScene g = GenerateScene(1217);
  ASSERT_EQ(g.family, Family::kBox);
  EXPECT_EQ(CheckResume(LawScene(g.scene), g.steps, 42), "");
}

// A mirrored box whose bonds rest across gaps: their force is 0 in one frame and +-3e-20 N/m of
// rounding in the other, and the aperture law's branch follows the sign (a0 against a0 + m g):
// 0.085 Pa apart after two steps. The laws compare such runs before the step where the count of
// open bonds in compression parts, as at a contact's onset.
TEST(FoundByTheLaws, MirrorComparesBeforeAnOpenBondsApertureBranchParts) {
  const GeneratedScene g = GenerateScene(4306);
  ASSERT_EQ(g.family, Family::kBox);
  SceneMap mirror;
  mirror.turn = Turn::kMirrorX;
  const LawScene scene(g.scene);
  EXPECT_EQ(CheckIsometry(scene, g.steps, mirror, RoundingSpread(scene, g.steps)), "");
}

// Local damping, F - alpha |F| sign(v), is off for a component at rest: |v| at most 1e-9 of the
// velocity its force gives in a step. A translated box (seed 3514, 4614 alike) had one loaded
// component on the threshold's other side in one frame at step 2, and the frames stayed 1.5e-8
// of K_f apart from step 3 on. The laws compare such runs before the step where the count of
// loaded components at rest parts (DemCounters::local_damping_at_rest), as at a contact's onset.
TEST(FoundByTheLaws, TranslationComparesBeforeLocalDampingsRestCountParts) {
  for (const std::uint64_t seed : {3514u, 4614u}) {
    const GeneratedScene g = GenerateScene(seed);
    ASSERT_EQ(g.family, Family::kBox) << seed;
    const LawScene scene(g.scene);
    EXPECT_EQ(CheckIsometry(scene, g.steps, SeedTranslation(seed), RoundingSpread(scene, g.steps)),
              "")
        << seed;
  }
}

// The energy guard's ratio K / (E_0 + W) over a run, and the run's status.
struct GuardedRun {
  Status status;
  double worst_ratio = 0.0;
  double final_ratio = 0.0;
};

GuardedRun RunGuarded(Simulation& sim, std::uint64_t from_step) {
  GuardedRun out;
  RunControl control;
  control.at_step_end = [&](const Simulation& at) {
    if (at.step() > from_step)
      out.worst_ratio = std::max(out.worst_ratio, at.stepper().EnergyRatio());
    out.final_ratio = at.stepper().EnergyRatio();
  };
  out.status = sim.Run(control);
  return out;
}

// An undamped box with no dashpots and disks apart: nothing dissipates and nothing is stored in
// contacts, so everything the pore fluid and walls give the disks is kinetic and the ratio is 1
// but for velocity-Verlet's error. With the work summed from each step's end force alone (k dx^2
// / 2 lost a step) the budget drained and the guard failed it at step 96 (641 times).
TEST(EnergyGuard, ALosslessSceneHoldsWhatItIsGiven) {
  const GeneratedScene g = GenerateScene(1949);
  Result<Simulation> sim = Simulation::Create(MaterialisedScene(g.scene));
  ASSERT_TRUE(sim.ok()) << sim.status().ToString();
  const GuardedRun run = RunGuarded(*sim, 8);
  ASSERT_TRUE(run.status.ok()) << run.status.ToString();
  EXPECT_GT(run.worst_ratio, 0.95);
  EXPECT_LT(run.worst_ratio, 1.05);
}

// The account is in the checkpoint: a run resumed mid-way ends with the uninterrupted run's ratio
// to the bit (so that it fails, or not, at the same step).
TEST(EnergyGuard, AResumedRunKeepsTheAccount) {
  const GeneratedScene g = GenerateScene(1949);
  const SceneSpec scene = MaterialisedScene(g.scene);
  Result<Simulation> whole = Simulation::Create(scene);
  ASSERT_TRUE(whole.ok());
  const GuardedRun uninterrupted = RunGuarded(*whole, 0);
  ASSERT_TRUE(uninterrupted.status.ok()) << uninterrupted.status.ToString();

  Result<Simulation> first = Simulation::Create(scene);
  ASSERT_TRUE(first.ok());
  std::stop_source stop;
  RunControl control;
  control.stop = stop.get_token();
  control.at_step_end = [&](const Simulation& at) {
    if (at.step() == 45) stop.request_stop();
  };
  ASSERT_EQ(first->Run(control).code(), StatusCode::kCancelled);
  Result<Simulation> second = Simulation::Create(scene);
  ASSERT_TRUE(second.ok());
  ASSERT_TRUE(second->Restore(first->TakeSnapshot()).ok());
  const GuardedRun resumed = RunGuarded(*second, 0);
  ASSERT_TRUE(resumed.status.ok()) << resumed.status.ToString();
  EXPECT_EQ(resumed.final_ratio, uninterrupted.final_ratio);
}

}  // namespace
}  // namespace seep::core::metamorphic
