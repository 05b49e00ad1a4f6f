// The DEM step follows the pore fluid's stiffness through re-detections (stepper.h, the clock):
// a random packing with fluid in its pores is pressed by a servo lid, so contacts form, domains
// split into smaller, stiffer pores, and after each re-detection the step must resolve the new
// network's fluid spring: dt <= (1/dt_c^2 + 1/dt_f^2)^(-1/2) with dt_c the contacts' stable step
// and dt_f the fluid's (fluid_stable_step.h), both measured by the test at that moment. The step
// must have shortened at least once, and a run resumed after it ends bit-identical to an
// uninterrupted one (the checkpoint carries the clock).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <stop_token>
#include <variant>

#include "coupled_scenes.h"
#include "seep/core/dem/dem_integrator.h"
#include "seep/core/effects/fluid_stable_step.h"

namespace seep::core {
namespace {

using effects_test::Contacts;
using effects_test::MustCreate;
using effects_test::MustRun;

// 120 disks of 0.8-1 mm, grown to a loose 0.25 box porosity, in the boxed scene's fluid
// (K_f = 2e8 Pa, stiff enough to limit the step) but sealed, without gravity, its lid pressing at
// 50 kPa, and with re-detection.
SceneSpec PressedRandomPacking() {
  SceneSpec s = effects_test::BoxedLatticeScene(1, 1);
  s.name = "pressed random packing";
  RandomPackingSpec r;
  r.seed = 7;
  r.width_m = 0.02;
  r.height_m = 0.02;
  r.min_radius_m = 0.8e-3;
  r.max_radius_m = 1.0e-3;
  r.particle_count = 120;
  r.target_porosity = 0.25;
  s.packing.source = r;
  s.solver.storage_floor_fraction = 0.05;
  s.solver.end_time_s = 4e-3;
  WallsEffectSpec walls;
  walls.walls = {SideWall(WallSide::kBottom), SideWall(WallSide::kLeft), SideWall(WallSide::kRight),
                 SideWall(WallSide::kTop, 5e4, 0.5, 0.2)};
  std::erase_if(s.effects, [](const EffectSpec& e) {
    return std::holds_alternative<GravityEffectSpec>(e) ||
           std::holds_alternative<WallsEffectSpec>(e);
  });
  s.effects.push_back(walls);
  s.effects.push_back(RedetectionEffectSpec{});
  return s;
}

TEST(DemStepRetune, ReDetectedStifferPoresShortenTheStep) {
  const SceneSpec scene = PressedRandomPacking();
  const ContactsEffectSpec contacts = Contacts();
  Simulation sim = MustCreate(scene);
  const double first_dt = sim.dt_s();
  std::uint64_t topology = 0;
  int checked = 0;
  RunControl control;
  control.at_step_end = [&](const Simulation& s) {
    const LiveState& state = s.stepper().state();
    if (state.topology_version == topology || s.finished()) return;
    topology = state.topology_version;
    const Result<double> contact_dt = EstimateStableTimeStep(state.particles, contacts.law.kn,
                                                             contacts.law.kt, contacts.dt_safety);
    ASSERT_TRUE(contact_dt.ok());
    const double fluid_dt = FluidStableStep(state, contacts.dt_safety);
    const double bound =
        1.0 / std::sqrt(1.0 / (*contact_dt * *contact_dt) + 1.0 / (fluid_dt * fluid_dt));
    EXPECT_LE(s.dt_s(), bound * (1.0 + 1e-12)) << "after the re-detection at step " << s.step();
    ++checked;
  };
  const Status run = sim.Run(control);
  ASSERT_TRUE(run.ok()) << run.message();
  std::printf("%d re-detections; DEM step %.6g s -> %.6g s, %llu steps\n", checked, first_dt,
              sim.dt_s(), static_cast<unsigned long long>(sim.step()));
  EXPECT_GT(checked, 0);
  EXPECT_LT(sim.dt_s(), first_dt);
  // The clock still lands on the end: the last step reaches end_time_s, the one before not.
  EXPECT_GE(sim.time_s(), scene.solver.end_time_s * (1.0 - 1e-12));
  EXPECT_LT(sim.time_s() - sim.dt_s(), scene.solver.end_time_s);
}

TEST(DemStepRetune, ResumeAfterTheStepShortenedIsBitIdentical) {
  const SceneSpec scene = PressedRandomPacking();
  Simulation reference = MustCreate(scene);
  const double first_dt = reference.dt_s();
  MustRun(reference);
  const SimulationSnapshot expected = reference.TakeSnapshot();

  Simulation first = MustCreate(scene);
  std::stop_source stop;
  RunControl control;
  control.stop = stop.get_token();
  std::uint64_t stop_at = 0;
  control.at_step_end = [&](const Simulation& s) {
    if (stop_at == 0 && s.dt_s() < first_dt) stop_at = s.step() + 5;
    if (s.step() == stop_at) stop.request_stop();
  };
  ASSERT_EQ(first.Run(control).code(), StatusCode::kCancelled);
  const SimulationSnapshot mid = first.TakeSnapshot();
  ASSERT_TRUE(mid.mechanics);
  EXPECT_LT(mid.mechanics->dt, first_dt);

  Simulation resumed = MustCreate(scene);
  const Status restored = resumed.Restore(mid);
  ASSERT_TRUE(restored.ok()) << restored.message();
  EXPECT_EQ(resumed.dt_s(), first.dt_s());
  EXPECT_EQ(resumed.total_steps(), first.total_steps());
  MustRun(resumed);
  const SimulationSnapshot got = resumed.TakeSnapshot();
  EXPECT_EQ(got.step, expected.step);
  EXPECT_EQ(std::memcmp(&got.time_s, &expected.time_s, sizeof(double)), 0);
  ASSERT_TRUE(got.mechanics && expected.mechanics);
  EXPECT_EQ(got.mechanics->x, expected.mechanics->x);
  EXPECT_EQ(got.mechanics->y, expected.mechanics->y);
  EXPECT_EQ(got.pressure, expected.pressure);
  EXPECT_EQ(got.series.values, expected.series.values);
  // And the same metrics: the run's counts (re-detections among them) are the run's, not this
  // process's since its restore.
  const RunReport want = reference.Report();
  const RunReport have = resumed.Report();
  ASSERT_EQ(have.metrics.size(), want.metrics.size());
  bool redetected = false;
  for (std::size_t k = 0; k < want.metrics.size(); ++k) {
    const auto& [name, value] = want.metrics[k];
    EXPECT_EQ(have.metrics[k].first, name);
    EXPECT_EQ(std::memcmp(&have.metrics[k].second, &value, sizeof(double)), 0)
        << name << ": resumed " << have.metrics[k].second << ", uninterrupted " << value;
    if (name == "redetections") redetected = value > 0.0;
  }
  EXPECT_TRUE(redetected) << "the scene must re-detect before the resume point for this test";
}

}  // namespace
}  // namespace seep::core
