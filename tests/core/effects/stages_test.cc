// Stages (scene.stages): settings that change at a stage's start or follow a schedule, end
// conditions, per-stage metrics, the series' stage column, failures at a stage's max duration,
// bit-identical resume mid-stage, and the validation that names the field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "coupled_scenes.h"

namespace seep::core {
namespace {

using effects_test::BoxedLatticeScene;
using effects_test::Contacts;
using effects_test::kRadius;
using effects_test::Metric;
using effects_test::MustCreate;
using effects_test::MustRun;
using effects_test::ResumedAt;
using effects_test::Stage;

constexpr double kTarget = 1e5;  // Pa, the confining stress of the DEM box
constexpr double kTolerance = 0.02;

StageWallSpec WallControl(std::uint32_t wall) {
  StageWallSpec w;
  w.wall = wall;
  return w;
}

// A dry 8 x 8 hex lattice in a box whose lid (wall 3) is a servo at kTarget, damped; three stages:
// confine until the lid holds its stress, rest with the lid fixed until the motion dies down,
// then lift the lid by a velocity schedule (a ramp to 0.05 m/s over 2 ms, then held for 2 ms).
SceneSpec DryBoxInStages() {
  SceneSpec s;
  s.name = "dry box in stages";
  s.packing.source = LatticePackingSpec{LatticeKind::kHex, 8, 8, kRadius};
  s.packing.contact_gap_m = 1e-6;
  s.aperture.residual_aperture_m = 1e-5;
  s.solver.kind = SolverKind::kExplicit;
  WallsEffectSpec walls;
  walls.walls = {SideWall(WallSide::kBottom), SideWall(WallSide::kLeft), SideWall(WallSide::kRight),
                 SideWall(WallSide::kTop, kTarget, 0.5, 0.05)};
  s.effects = {Contacts(), walls, LocalDampingEffectSpec{0.7}};
  s.stages.push_back(Stage("confine", {ServoHeldEnd{kTolerance, 1e-3}}, 0.2));
  StageSpec rest = Stage("rest", {KineticEnergyEnd{0.01}}, 0.2);
  StageWallSpec fixed = WallControl(3);
  fixed.fixed = true;
  rest.walls = {fixed};
  s.stages.push_back(rest);
  StageSpec lift = Stage("lift", {DurationEnd{4e-3}});
  StageWallSpec lid = WallControl(3);
  lid.normal_velocity_m_s = ScheduleSpec{{0.0, 2e-3}, {0.0, -0.05}};
  lift.walls = {lid};
  s.stages.push_back(lift);
  return s;
}

TEST(Stages, ScheduleIsLinearBetweenItsPointsAndHeldBeyondThem) {
  const SettingSpec schedule = ScheduleSpec{{1.0, 2.0, 4.0}, {10.0, 20.0, -20.0}};
  EXPECT_EQ(SettingAt(schedule, 0.0), 10.0);
  EXPECT_EQ(SettingAt(schedule, 1.0), 10.0);
  EXPECT_DOUBLE_EQ(SettingAt(schedule, 1.5), 15.0);
  EXPECT_EQ(SettingAt(schedule, 2.0), 20.0);
  EXPECT_DOUBLE_EQ(SettingAt(schedule, 3.0), 0.0);
  EXPECT_EQ(SettingAt(schedule, 9.0), -20.0);
  EXPECT_EQ(SettingEnd(schedule), -20.0);
  EXPECT_EQ(SettingAt(SettingSpec{7.0}, 123.0), 7.0);
}

TEST(Stages, ConfineRestAndLiftEachEndOnTheirOwnCondition) {
  Simulation sim = MustCreate(DryBoxInStages());
  std::vector<std::uint32_t> stages_seen;
  RunControl control;
  control.on_progress = [&](const RunProgress& p) {
    EXPECT_EQ(p.stage_count, 3u);
    if (stages_seen.empty() || stages_seen.back() != p.stage_index) {
      stages_seen.push_back(p.stage_index);
    }
  };
  const Status run = sim.Run(control);
  ASSERT_TRUE(run.ok()) << run.message();
  const RunReport r = sim.Report();
  const double dt = Metric(r, "dem_dt_s");
  std::printf("confine %.4g s (lid %.6g Pa), rest %.4g s, lift %.4g s\n",
              Metric(r, "stage1_duration_s"), Metric(r, "stage1_top_wall_stress_pa"),
              Metric(r, "stage2_duration_s"), Metric(r, "stage3_duration_s"));
  EXPECT_EQ(Metric(r, "stages_ended"), 3.0);
  // Confine ended by its servo condition (not its max duration): the lid held its target.
  EXPECT_EQ(Metric(r, "stage1_ended_by"), 0.0);
  EXPECT_NEAR(Metric(r, "stage1_top_wall_stress_pa"), kTarget, kTolerance * kTarget);
  EXPECT_GE(Metric(r, "stage1_duration_s"), 1e-3);
  // Rest ended when the kinetic energy fell to 1 % of its peak.
  EXPECT_EQ(Metric(r, "stage2_ended_by"), 0.0);
  // The fixed lid did not move during the rest.
  EXPECT_EQ(Metric(r, "stage2_top_wall_position_m"), Metric(r, "stage1_top_wall_position_m"));
  // Lift: the lid moved outwards by the integral of its velocity schedule, 0.05 m/s x (1 ms of
  // the ramp's mean + 2 ms held) = 1.5e-4 m. The velocity is taken at each step's start (a left
  // Riemann sum, off by at most v_max dt) and the stage may overrun 4 ms by less than a step.
  EXPECT_EQ(Metric(r, "stage3_ended_by"), 0.0);
  EXPECT_GE(Metric(r, "stage3_duration_s"), 4e-3 - 1e-6 * dt);
  EXPECT_LT(Metric(r, "stage3_duration_s"), 4e-3 + dt);
  const double lifted = Metric(r, "top_wall_position_m") - Metric(r, "stage2_top_wall_position_m");
  EXPECT_NEAR(lifted, 1.5e-4, 2.0 * 0.05 * dt);
  // The run's end is the last stage's end, and progress named each stage in turn.
  EXPECT_DOUBLE_EQ(Metric(r, "simulated_time_s"), Metric(r, "stage1_duration_s") +
                                                      Metric(r, "stage2_duration_s") +
                                                      Metric(r, "stage3_duration_s"));
  EXPECT_EQ(stages_seen, (std::vector<std::uint32_t>{1, 2, 3}));
  // The series' stage column marks the stages in order, ending in the last.
  const TimeSeries& series = r.series;
  ASSERT_EQ(series.columns.back(), "stage");
  const std::size_t width = series.columns.size();
  double previous = 1.0;
  for (std::size_t row = 0; row < series.rows(); ++row) {
    const double stage = series.values[row * width + width - 1];
    EXPECT_GE(stage, previous);
    previous = stage;
  }
  EXPECT_EQ(previous, 3.0);
}

TEST(Stages, MaxDurationFailsTheRunNamingTheStageOrMovesOn) {
  SceneSpec scene = DryBoxInStages();
  // A rest that cannot end by its condition within 1 ms (the damped motion needs longer).
  scene.stages[1].end = {KineticEnergyEnd{1e-12}};
  scene.stages[1].max_duration_s = 1e-3;
  Simulation failing = MustCreate(scene);
  const Status failed = failing.Run({});
  EXPECT_EQ(failed.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(failed.message().find("stage 2/3 'rest' (scene.stages[1]): reached max_duration_s = "
                                  "0.001 s"),
            std::string::npos)
      << failed.message();
  scene.stages[1].continue_at_max_duration = true;
  Simulation moving_on = MustCreate(scene);
  MustRun(moving_on);
  const RunReport r = moving_on.Report();
  EXPECT_EQ(Metric(r, "stage2_ended_by"), -1.0);
  EXPECT_NEAR(Metric(r, "stage2_duration_s"), 1e-3, Metric(r, "dem_dt_s"));
  EXPECT_EQ(Metric(r, "stages_ended"), 3.0);
}

// Linear permeameter on a rigid square lattice (implicit solver, steps far longer than the
// diffusion time): the inlet pressure is 1e5 Pa in the first stage and 3e5 Pa in the second; each
// stage ends at a steady state whose permeability is the lattice's exact one, a0^3 / (24 R).
TEST(Stages, PermeameterStepsItsInletPressureAndEndsEachStageOnItsDuration) {
  SceneSpec s;
  s.name = "permeameter in stages";
  s.packing.source = LatticePackingSpec{LatticeKind::kSquare, 31, 4, 1e-3};
  s.packing.contact_gap_m = 1e-9;
  s.aperture.residual_aperture_m = 1e-5;
  s.boundary.axis = FlowAxis::kX;
  s.boundary.inlet_pressure_pa = 1e5;
  s.solver.kind = SolverKind::kImplicit;
  s.solver.dt_factor = 1e4;
  StageSpec low = Stage("low", {DurationEnd{0.5}});
  StageSpec high = Stage("high", {DurationEnd{0.5}});
  high.inlet_pressure_pa = 3e5;
  s.stages = {low, high};
  Simulation sim = MustCreate(s);
  MustRun(sim);
  const RunReport r = sim.Report();
  const double exact = Metric(r, "lattice_permeability_m2");
  EXPECT_NEAR(Metric(r, "stage1_permeability_m2"), exact, 1e-9 * exact);
  EXPECT_NEAR(Metric(r, "permeability_m2"), exact, 1e-9 * exact);
  EXPECT_NEAR(Metric(r, "inflow_m2_per_s") / Metric(r, "stage1_inflow_m2_per_s"), 3.0, 1e-9);
  // A frozen scene's stage lands on its duration exactly.
  EXPECT_EQ(Metric(r, "stage1_simulated_time_s"), 0.5);
  EXPECT_EQ(Metric(r, "simulated_time_s"), 1.0);
}

template <typename T>
bool VectorsBitEqual(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// The coupled box (walls that bound the fluid, drained side platens) in stages: confine until
// the lid holds 2e4 Pa, then raise the left platen's pressure by a schedule from 2e4 to 5e4 Pa
// over 1 ms and hold it for 1 ms more. Stopped inside each stage and resumed in a fresh
// simulation, the run ends bit-identical to the uninterrupted one.
SceneSpec CoupledBoxInStages() {
  SceneSpec s = BoxedLatticeScene(8, 8);
  s.solver.end_time_s = 0.0;
  s.stages.push_back(Stage("confine", {ServoHeldEnd{0.05, 2e-4}}, 0.02));
  StageSpec drive = Stage("drive", {DurationEnd{2e-3}});
  StageWallSpec left = WallControl(1);
  left.drain_pressure_pa = ScheduleSpec{{0.0, 1e-3}, {2e4, 5e4}};
  drive.walls = {left};
  s.stages.push_back(drive);
  return s;
}

TEST(Stages, ResumedInsideEachStageEndsBitIdentical) {
  const SceneSpec scene = CoupledBoxInStages();
  Simulation whole = MustCreate(scene);
  MustRun(whole);
  const SimulationSnapshot expected = whole.TakeSnapshot();
  const RunReport report = whole.Report();
  EXPECT_EQ(Metric(report, "stage1_ended_by"), 0.0);
  // The platen took the schedule's last value.
  const SceneNetwork& net = whole.network();
  EXPECT_EQ(net.flow.pressure()[static_cast<std::size_t>(net.wall_node[1])], 5e4);
  const std::uint64_t stage1_end = static_cast<std::uint64_t>(Metric(report, "stage1_steps"));
  for (const std::uint64_t stop_at : {stage1_end / 2, stage1_end + 7}) {
    SimulationSnapshot mid;
    Simulation resumed = ResumedAt(
        scene, [&](const Simulation& s) { return s.step() == stop_at; }, &mid);
    ASSERT_TRUE(mid.stages.has_value());
    EXPECT_EQ(mid.stages->index, stop_at < stage1_end ? 0u : 1u);
    MustRun(resumed);
    const SimulationSnapshot got = resumed.TakeSnapshot();
    EXPECT_EQ(got.step, expected.step);
    EXPECT_EQ(std::memcmp(&got.time_s, &expected.time_s, sizeof(double)), 0);
    EXPECT_TRUE(VectorsBitEqual(got.pressure, expected.pressure));
    EXPECT_TRUE(VectorsBitEqual(got.mechanics->x, expected.mechanics->x));
    EXPECT_TRUE(VectorsBitEqual(got.mechanics->y, expected.mechanics->y));
    EXPECT_TRUE(VectorsBitEqual(got.mechanics->walls, expected.mechanics->walls));
    EXPECT_TRUE(VectorsBitEqual(got.series.values, expected.series.values));
    ASSERT_TRUE(got.stages && expected.stages);
    EXPECT_EQ(got.stages->ended_metrics, expected.stages->ended_metrics);
    EXPECT_EQ(got.stages->index, 2u);
  }
}

// Bad stages: each refusal names the field and the reason.
TEST(Stages, ValidationNamesTheField) {
  const auto expect = [](const SceneSpec& scene, const std::string& start) {
    const Status status = ValidateScene(scene);
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << start;
    EXPECT_EQ(status.message().rfind(start, 0), 0u) << status.message();
  };
  const SceneSpec good = DryBoxInStages();
  ASSERT_TRUE(ValidateScene(good).ok()) << ValidateScene(good).message();

  SceneSpec s = good;
  s.stages[1].end = {BondsBrokenEnd{5}};
  expect(s, "scene.stages[1].end[0].bonds_broken: the scene does not list the bonds effect");
  s = good;
  s.stages[2].end = {BreakthroughEnd{}};
  expect(s, "scene.stages[2].end[0].breakthrough: the scene does not list the redetection effect");
  s = good;
  s.stages[0].injection_rate_m2_s = 1e-6;
  expect(s, "scene.stages[0].injection_rate_m2_s: the scene does not list the injection effect");
  s = good;
  s.stages[2].walls[0].normal_velocity_m_s = ScheduleSpec{{0.0, 2e-3, 2e-3}, {0.0, 1.0, 2.0}};
  expect(s,
         "scene.stages[2].walls[0].normal_velocity_m_s.schedule.time_s[2]: must be greater than "
         "time_s[1] (a schedule is increasing in time");
  s = good;
  s.stages[2].walls[0].normal_velocity_m_s = ScheduleSpec{{0.0, 1e-3}, {0.0}};
  expect(s, "scene.stages[2].walls[0].normal_velocity_m_s.schedule.value: 1 values for 2 times");
  s = good;
  s.stages[0].end = {KineticEnergyEnd{0.1}};
  s.stages[0].max_duration_s = 0.0;
  expect(s, "scene.stages[0].max_duration_s: must be > 0 when no duration_s or steps condition");
  s = good;
  s.stages[0].end.clear();
  expect(s, "scene.stages[0].end: a stage needs at least one end condition");
  s = good;
  s.solver.end_time_s = 1.0;
  expect(s, "scene.solver.end_time_s: must be 0 (unset) in a scene with stages");
  s = good;
  s.stages[1].walls[0].wall = 7;
  expect(s, "scene.stages[1].walls[0].wall: the walls effect has 4 walls (got index 7)");
  s = good;
  StageWallSpec floor = WallControl(0);
  floor.servo_stress_pa = 1e5;
  s.stages[0].walls = {floor};
  expect(s,
         "scene.stages[0].walls[0].servo_stress_pa: wall 0 of the walls effect has no "
         "servo_max_speed_m_s");
  s = good;
  s.stages[1].walls[0].normal_velocity_m_s = 0.01;
  expect(s, "scene.stages[1].walls[0]: set one of servo_stress_pa, normal_velocity_m_s and fixed");
  s = good;
  s.stages[2].end.push_back(DurationEnd{1.0});
  expect(s, "scene.stages[2].end[1].duration_s: this condition is listed twice");
  s = good;
  s.stages[0].end = {ServoHeldEnd{0.0, 1e-3}};
  expect(s, "scene.stages[0].end[0].servo_held.tolerance_fraction: must lie in (0, 1)");
  s = good;
  s.stages[0].inlet_pressure_pa = 1.0;
  expect(s, "scene.stages[0].inlet_pressure_pa: the scene does not list the flow effect");
  // The lid is a servo in the scene; stage 1 fixes it, so a servo condition after that is empty.
  s = good;
  s.stages[2].end = {ServoHeldEnd{0.1, 0.0}};
  s.stages[2].walls.clear();
  expect(s, "scene.stages[2].end[0].servo_held: no wall is servo-controlled in this stage");
}

}  // namespace
}  // namespace seep::core
