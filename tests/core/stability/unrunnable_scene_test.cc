// A scene or network that cannot be run stably with the chosen solver fails before any number is
// produced, with a message that names the field, says why, and says what to change (issue 7).
// Next to each refusal, the nearest runnable choice runs and keeps the invariants.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "flow_test_networks.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/run/simulation.h"
#include "stability_invariants.h"

namespace seep::core {
namespace {

constexpr double kUnrunnableInlet = 1e5;  // Pa

// A rigid 10 x 8 square-lattice permeameter with water, run transiently for 2 ms.
SceneSpec TransientScene(SolverKind kind, double dt_factor) {
  SceneSpec s;
  s.name = "stability";
  s.packing.source = LatticePackingSpec{LatticeKind::kSquare, 10, 8, 1e-3};
  s.fluid.viscosity_pa_s = 1e-3;
  s.fluid.bulk_modulus_pa = 2.2e9;
  s.aperture.residual_aperture_m = 1e-5;
  s.boundary.inlet_pressure_pa = kUnrunnableInlet;
  s.boundary.outlet_pressure_pa = 0.0;
  s.solver.kind = kind;
  s.solver.dt_factor = dt_factor;
  s.solver.end_time_s = 2e-3;
  return s;
}

// Every part must appear in the message; the test output shows the whole message when one is
// missing.
void ExpectMessage(const Status& status, StatusCode code, const std::vector<std::string>& parts) {
  EXPECT_EQ(status.code(), code) << status.ToString();
  for (const std::string& part : parts) {
    EXPECT_NE(status.message().find(part), std::string::npos)
        << "missing '" << part << "' in: " << status.message();
  }
}

double MetricOf(const RunReport& report, const std::string& name) {
  for (const auto& [key, value] : report.metrics) {
    if (key == name) return value;
  }
  ADD_FAILURE() << "metric " << name << " is missing";
  return 0.0;
}

// Runs a scene to the end and checks the run's own budget and pressure range.
void ExpectRunsBoundedAndConservative(const SceneSpec& scene) {
  auto sim = Simulation::Create(scene);
  ASSERT_TRUE(sim.ok()) << sim.status().ToString();
  ASSERT_TRUE(sim->Run({}).ok());
  const RunReport report = sim->Report();
  EXPECT_LE(MetricOf(report, "mass_balance_error_max"), stability::kMassTolerance);
  EXPECT_GE(MetricOf(report, "min_pressure_pa"), -1e-12 * kUnrunnableInlet);
  EXPECT_LE(MetricOf(report, "max_pressure_pa"), kUnrunnableInlet * (1 + 1e-12));
  EXPECT_EQ(MetricOf(report, "dt_over_dt_crit"), scene.solver.dt_factor);
  EXPECT_TRUE(stability::AllFinite(sim->network().flow));
}

TEST(Stability, ExplicitSceneAboveCriticalStepIsRefusedByValidation) {
  const auto sim = Simulation::Create(TransientScene(SolverKind::kExplicit, 1.05));
  ASSERT_FALSE(sim.ok());
  ExpectMessage(sim.status(), StatusCode::kInvalidArgument,
                {"scene.solver.dt_factor:", "unstable above the critical step", "(0, 1]",
                 "implicit solver", "1.05"});
  // What the message proposes runs: explicit at exactly the limit, implicit at 100x.
  ExpectRunsBoundedAndConservative(TransientScene(SolverKind::kExplicit, 1.0));
  ExpectRunsBoundedAndConservative(TransientScene(SolverKind::kImplicit, 100.0));
}

// Regression: an explicit scene at dt_factor 1 once failed at its last step when end_time_s was
// within ~1e-12 of a multiple of dt: the last step, the time left after summing the steps, came out
// an ulp above dt_crit and the governor refused it. It is now never longer than dt.
TEST(Stability, ExplicitSceneAtTheCriticalStepFinishesWhenEndTimeIsAMultipleOfDt) {
  const auto probe = Simulation::Create(TransientScene(SolverKind::kExplicit, 1.0));
  ASSERT_TRUE(probe.ok()) << probe.status().ToString();
  SceneSpec scene = TransientScene(SolverKind::kExplicit, 1.0);
  scene.solver.end_time_s = 100.0 * probe->dt_s();
  auto sim = Simulation::Create(scene);
  ASSERT_TRUE(sim.ok()) << sim.status().ToString();
  const Status run = sim->Run({});
  EXPECT_TRUE(run.ok()) << run.ToString();
}

TEST(Stability, SceneWithoutFlowDomainsIsRefusedWithTheRemedy) {
  // Three disks far apart: no closed loop, so no domain and no flow at all.
  SceneSpec s = TransientScene(SolverKind::kExplicit, 0.9);
  s.packing.source = ParticleListSpec{{0.0, 1.0, 2.0}, {0.0, 0.0, 1.0}, {1e-3, 1e-3, 1e-3}};
  const auto sim = Simulation::Create(s);
  ASSERT_FALSE(sim.ok());
  ExpectMessage(sim.status(), StatusCode::kFailedPrecondition,
                {"scene.packing:", "encloses no domain", "raise packing.contact_gap_m"});
}

TEST(Stability, ClosedNetworkSteadySolveSaysWhichComponentAndWhatToFix) {
  FlowNetwork net = testing::MakeOrDie(testing::MakeRandomClosedData(12, 6, 3));
  const auto r = SolveSteadyState(net);
  ASSERT_FALSE(r.ok());
  ExpectMessage(r.status(), StatusCode::kFailedPrecondition,
                {"flow.steady: component 0", "has no fixed-pressure domain",
                 "scene.boundary.regions", "scene.solver.kind", "kConserveStoredFluid"});
}

TEST(Stability, ZeroVolumeDomainIsRefusedByEveryTransientSolver) {
  FlowNetworkData d = testing::MakeRandomClosedData(12, 6, 3);
  d.pore_volume[5] = 0.0;  // a sliver collapsed to nothing
  FlowNetwork net = testing::MakeOrDie(std::move(d));
  const std::vector<std::string> parts = {
      "flow.network.pore_volume[5]:", "must be > 0",
      "set a volume floor (scene.solver.storage_floor_fraction)"};
  auto explicit_solver = ExplicitSolver::Create({});
  ASSERT_TRUE(explicit_solver.ok());
  ExpectMessage(explicit_solver->Step(net, 1e-9).status(), StatusCode::kInvalidArgument, parts);
  auto implicit_solver = ImplicitSolver::Create({});
  ASSERT_TRUE(implicit_solver.ok());
  ExpectMessage(implicit_solver->Step(net, 1e-9).status(), StatusCode::kInvalidArgument, parts);
  EXPECT_TRUE(stability::AllFinite(net));  // nothing was written
}

TEST(Stability, ExplicitSafetyFactorAboveOneIsRefused) {
  ExplicitSolverOptions opt;
  opt.safety_factor = 1.5;
  const auto solver = ExplicitSolver::Create(opt);
  ASSERT_FALSE(solver.ok());
  ExpectMessage(solver.status(), StatusCode::kInvalidArgument,
                {"flow.explicit.safety_factor:", "must be in (0, 1]", "1.5"});
}

}  // namespace
}  // namespace seep::core

namespace seep::core {
namespace {

// A step count past what a run can count (issue 50: end_time_s 1e15 or dt_factor 1e-20 overflowed
// the cast to 64 bits, and the job "succeeded" after one step).
TEST(Stability, AStepCountPastWhatARunCanCountIsRefusedNamingTheFields) {
  for (const auto& [end_time, dt_factor] : {std::pair{1e15, 0.9}, std::pair{2e-3, 1e-20}}) {
    SceneSpec scene = TransientScene(SolverKind::kExplicit, dt_factor);
    scene.solver.end_time_s = end_time;
    const auto sim = Simulation::Create(scene);
    ExpectMessage(sim.status(), StatusCode::kInvalidArgument,
                  {"solver.end_time_s", "solver.dt_factor", "2^53"});
  }
  // Far below the bound, a long run is still accepted (it is bounded by the service's limits).
  SceneSpec scene = TransientScene(SolverKind::kImplicit, 1.0);
  scene.solver.end_time_s = 1e3;
  EXPECT_TRUE(Simulation::Create(scene).ok());
}

// A frozen packing with gravity and a fluid density but no flow effect ran nothing and crashed
// the stepper (issue 50): it is refused, saying what to add.
TEST(Stability, AFrozenPackingWithGravityAloneIsRefusedSayingToAddFlow) {
  SceneSpec scene = TransientScene(SolverKind::kImplicit, 1.0);
  scene.fluid.density_kg_m3 = 1000.0;
  scene.effects = {GravityEffectSpec{}};
  ExpectMessage(ValidateScene(scene), StatusCode::kInvalidArgument, {"scene.effects", "flow"});
  ExpectMessage(Simulation::Create(scene).status(), StatusCode::kInvalidArgument,
                {"scene.effects", "flow"});
  scene.effects.push_back(FlowEffectSpec{});
  auto sim = Simulation::Create(scene);
  ASSERT_TRUE(sim.ok()) << sim.status().ToString();
  EXPECT_TRUE(sim->Run({}).ok());
}

}  // namespace
}  // namespace seep::core
