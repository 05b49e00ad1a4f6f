// Boundary regions (scene.boundary.regions, network/boundary_regions.h): fixed pressures and
// fixed fluxes on the domains inside shapes, each checked against an independent value — the
// lattice's exact conductance, Thiem's radial solution, the set rate, the books' balance, and
// the flow of each stage of a staged run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stop_token>
#include <string>
#include <variant>
#include <vector>

#include "../effects/coupled_scenes.h"  // the coupled sample the moving test starts from
#include "scene_test_util.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/reference/analytic_solutions.h"
#include "seep/core/reference/radial_profile.h"
#include "seep/core/run/simulation.h"

namespace seep::core {
namespace {

using scene_test::kAperture;
using scene_test::kRadius;
using scene_test::kViscosity;
using scene_test::Metric;

BoundaryRegionSpec Region(std::string name, RegionShape shape, RegionCondition condition) {
  return BoundaryRegionSpec{std::move(name), std::move(shape), condition};
}

// The conductance of one pipe of a rigid lattice, a^3 / (12 mu L) with L = 2R.
double LatticePipeConductance() {
  return kAperture * kAperture * kAperture / (12.0 * kViscosity * 2.0 * kRadius);
}

// A square lattice of `columns` x `rows` disks whose first and last columns of domains (centroids
// at x = 2R and x = 2 (columns - 1) R) are held by two half-plane pressure regions. The linear
// boundary's reservoirs touch only those domains, so they carry nothing the sample sees.
SceneSpec EndRegionsLattice(std::uint32_t columns, std::uint32_t rows, double p_left,
                            double p_right) {
  SceneSpec s = scene_test::LatticeScene(LatticeKind::kSquare, columns, rows, FlowAxis::kX);
  const double x_last = 2.0 * (columns - 1) * kRadius;
  s.boundary.regions = {
      Region("left", HalfPlaneShape{3.0 * kRadius, 0.0, -1.0, 0.0}, FixedPressure{p_left}),
      Region("right", HalfPlaneShape{x_last - kRadius, 0.0, 1.0, 0.0}, FixedPressure{p_right})};
  return s;
}

RunReport MustRun(const SceneSpec& scene) {
  Result<Simulation> sim = Simulation::Create(scene);
  EXPECT_TRUE(sim.ok()) << sim.status().message();
  if (!sim.ok()) return {};
  const Status run = sim->Run({});
  EXPECT_TRUE(run.ok()) << run.message();
  return sim->Report();
}

// (1) Two half-plane pressure regions at the ends of a rigid square lattice: every row of domains
// is a chain of (columns - 2) equal pipes between them and the rows carry the same pressures, so
// no pipe across the rows carries flow and Q = (rows - 1) C dP / (columns - 2) exactly — Darcy's
// a^3/(24R) over the regions' distance. A direct solve of ~350 unknowns rounds to ~1e-13 of Q.
TEST(BoundaryRegions, HalfPlanePressureRegionsGiveTheLatticesLinearFlow) {
  constexpr std::uint32_t kColumns = 40, kRows = 10;
  constexpr double kLeft = 2e5, kRight = 5e4;
  const RunReport r = MustRun(EndRegionsLattice(kColumns, kRows, kLeft, kRight));
  const double q = (kRows - 1) * LatticePipeConductance() * (kLeft - kRight) / (kColumns - 2);
  const double into_right = Metric(r, "region_right_flow_m2_per_s");
  const double into_left = Metric(r, "region_left_flow_m2_per_s");
  std::printf("regions: Q = %.17g into the right region, %.17g analytic (rel. %.3g)\n", into_right,
              q, std::abs(into_right - q) / q);
  EXPECT_NEAR(into_right, q, 1e-10 * q);
  EXPECT_NEAR(into_left, -q, 1e-10 * q);  // out of the left region into the sample
  EXPECT_EQ(Metric(r, "region_left_domains"), kRows - 1.0);
  EXPECT_EQ(Metric(r, "region_right_domains"), kRows - 1.0);
  // The reservoirs see only fixed domains: they exchange nothing with the sample.
  EXPECT_EQ(Metric(r, "inflow_m2_per_s"), 0.0);
  EXPECT_EQ(Metric(r, "outflow_m2_per_s"), 0.0);
}

// The polygon of the square [x0, x1] x [y0, y1] above (upper = true) or below the line y = cy
// outside the disc of radius r about (cx, cy), the arc as `segments` chords of the circle.
PolygonShape OutsideDiscHalf(double x0, double y0, double x1, double y1, double cx, double cy,
                             double r, int segments, bool upper) {
  const double sign = upper ? 1.0 : -1.0;
  PolygonShape p;
  const auto add = [&p, cy, sign](double x, double dy) {
    p.x.push_back(x);
    p.y.push_back(cy + sign * dy);
  };
  const double edge = upper ? y1 - cy : cy - y0;
  add(x0, 0.0);
  for (int k = 0; k <= segments; ++k) {  // from angle pi to 0, over the top (or bottom)
    const double a = std::numbers::pi * (1.0 - static_cast<double>(k) / segments);
    add(cx + r * std::cos(a), r * std::sin(a));
  }
  add(x1, 0.0);
  add(x1, edge);
  add(x0, edge);
  return p;
}

// (2) A circle pressure region in the middle of a square lattice, the domains beyond r_e held by
// a second pressure condition (two half-square polygons with the same pressure, which overlap
// along their common edge: allowed). Thiem's p = A + B ln r between them; the fit over the domains
// well inside both regions gives the effective radii of the two staircase boundaries, and with
// them Thiem's rate 2 pi k (p_w - p_e) / (mu ln(r_e / r_w)) = -2 pi k B / mu. The lattice is
// isotropic (k = a^3/(24R) both ways); its five-point stencil errs on ln r by about
// (h / r)^2 / 12, h = 2R: 0.2 % at the window's inner edge r = 14 R and less beyond, in a cos 4
// theta pattern that the flow through a ring averages out. 0.5 % bounds the profile and the rate
// (measured: 9e-4 and 4e-5).
TEST(BoundaryRegions, CirclePressureRegionGivesThiemsRadialFlow) {
  constexpr std::uint32_t kSide = 61;  // the centre (61 R, 61 R) is a disk's, no domain's
  constexpr double kWell = 1e5, kOuter = 0.0;
  const double c = kSide * kRadius;
  const double r_w = 8.0 * kRadius, r_e = 50.0 * kRadius;
  SceneSpec s = scene_test::LatticeScene(LatticeKind::kSquare, kSide, kSide, FlowAxis::kX);
  const double x1 = 2.0 * kSide * kRadius;
  s.boundary.regions = {
      Region("well", CircleShape{c, c, r_w}, FixedPressure{kWell}),
      Region("outer_top", OutsideDiscHalf(0.0, 0.0, x1, x1, c, c, r_e, 256, true),
             FixedPressure{kOuter}),
      Region("outer_bottom", OutsideDiscHalf(0.0, 0.0, x1, x1, c, c, r_e, 256, false),
             FixedPressure{kOuter})};
  ASSERT_TRUE(ValidateScene(s).ok()) << ValidateScene(s).message();
  const RunReport report = MustRun(s);
  const double q_well = -Metric(report, "region_well_flow_m2_per_s");
  const double q_outer = Metric(report, "region_outer_top_flow_m2_per_s") +
                         Metric(report, "region_outer_bottom_flow_m2_per_s");
  EXPECT_NEAR(q_outer, q_well, 1e-10 * q_well);  // steady: what the well gives leaves outside

  Result<SceneNetwork> net = BuildSceneNetwork(s);
  ASSERT_TRUE(net.ok()) << net.status().message();
  ASSERT_TRUE(SolveSteadyState(net->flow).ok());
  net->well_x_m = net->well_y_m = c;  // the profile is measured about the circle's centre
  const double r_min = r_w + 3.0 * 2.0 * kRadius, r_max = r_e - 3.0 * 2.0 * kRadius;
  Result<RadialProfileFit> fit = FitRadialProfile(*net, r_min, r_max);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  const double r_w_eff = fit->EffectiveWellRadius(kWell);
  const double r_e_eff = fit->EffectiveWellRadius(kOuter);
  const double k = kAperture * kAperture * kAperture / (24.0 * kRadius);
  const double q_thiem = ThiemFlowRate(k, kViscosity, r_w_eff, r_e_eff, kWell, kOuter);
  double profile_error = 0.0;
  for (std::size_t i = 0; i < fit->ln_r.size(); ++i) {
    const double thiem = ThiemPressure(std::exp(fit->ln_r[i]), r_w_eff, r_e_eff, kWell, kOuter);
    profile_error = std::max(profile_error, std::abs(fit->pressure[i] - thiem) / (kWell - kOuter));
  }
  std::printf(
      "thiem: Q = %.6g, Thiem %.6g (rel. %.3g); r_w,eff = %.4g R (circle %.4g R), r_e,eff = %.4g R "
      "(%.4g R); profile within %.3g of dp over %zu domains\n",
      q_well, q_thiem, std::abs(q_well - q_thiem) / q_thiem, r_w_eff / kRadius, r_w / kRadius,
      r_e_eff / kRadius, r_e / kRadius, profile_error, fit->ln_r.size());
  EXPECT_GT(fit->ln_r.size(), 1000u);
  EXPECT_NEAR(q_well / q_thiem, 1.0, 0.005);
  EXPECT_LT(profile_error, 0.005);
  // The staircase boundaries sit within a domain (2R) of the circles they stand for.
  EXPECT_NEAR(r_w_eff, r_w, 2.0 * kRadius);
  EXPECT_NEAR(r_e_eff, r_e, 2.0 * kRadius);
}

// A square lattice with a circle flux region at its centre injecting kRate and a half-plane
// pressure region over the last column of domains; the inlet end is closed, so the fluid leaves
// through the pressure region only.
constexpr double kRate = 1e-6;  // m^2/s
SceneSpec FluxToOutletLattice(SolverKind kind) {
  constexpr std::uint32_t kSide = 21;
  SceneSpec s = scene_test::LatticeScene(LatticeKind::kSquare, kSide, kSide, FlowAxis::kX);
  s.boundary.closed_inlet = true;
  s.boundary.inlet_pressure_pa = 0.0;
  const double c = kSide * kRadius;
  s.boundary.regions = {
      Region("source", CircleShape{c, c, 4.0 * kRadius}, FixedFlux{kRate}),
      Region("outlet", HalfPlaneShape{2.0 * (kSide - 1) * kRadius - kRadius, 0.0, 1.0, 0.0},
             FixedPressure{0.0})};
  s.solver.kind = kind;
  s.fluid.bulk_modulus_pa = 2.2e9;
  if (kind != SolverKind::kSteady) {
    s.solver.dt_factor = kind == SolverKind::kExplicit ? 0.9 : 20.0;
    s.solver.end_time_s = 1e-3;
  }
  return s;
}

// (3a) Steady: what the flux region injects leaves through the pressure region, to the direct
// solve's rounding; the rate is split among the region's domains by V_d (all equal here).
TEST(BoundaryRegions, FluxRegionsRateLeavesThroughThePressureRegion) {
  const SceneSpec s = FluxToOutletLattice(SolverKind::kSteady);
  const RunReport r = MustRun(s);
  const double out = Metric(r, "region_outlet_flow_m2_per_s");
  std::printf("flux: outflow %.17g for a rate of %.17g (rel. %.3g)\n", out, kRate,
              std::abs(out - kRate) / kRate);
  EXPECT_NEAR(out, kRate, 1e-12 * kRate);
  EXPECT_NEAR(Metric(r, "region_source_flow_m2_per_s"), kRate, 1e-15 * kRate);
  // Centroids at odd multiples of R from the centre: 4 at 1.4 R and 8 at 3.2 R lie within 4 R.
  EXPECT_EQ(Metric(r, "region_source_domains"), 12.0);
  Result<SceneNetwork> net = BuildSceneNetwork(s);
  ASSERT_TRUE(net.ok()) << net.status().message();
  for (const std::int32_t d : net->regions[0].nodes) {
    EXPECT_EQ(net->flow.role()[static_cast<std::size_t>(d)], DomainRole::kSource);
    EXPECT_NEAR(net->flow.source_rate()[static_cast<std::size_t>(d)], kRate / 12.0, 1e-15 * kRate);
  }
}

// (3b) Transient, every solver: the books close to rounding with a pressure and a flux region;
// the flux region injected rate x time, and what did not leave is stored.
TEST(BoundaryRegions, TransientBooksCloseWithAPressureAndAFluxRegion) {
  for (const SolverKind kind :
       {SolverKind::kExplicit, SolverKind::kImplicit, SolverKind::kCrankNicolson}) {
    SCOPED_TRACE(static_cast<int>(kind));
    const RunReport r = MustRun(FluxToOutletLattice(kind));
    const double injected = Metric(r, "fluid_injected_m2");
    const double left = Metric(r, "fluid_left_region_outlet_m2");
    const double stored = Metric(r, "fluid_stored_m2");
    const double time = Metric(r, "simulated_time_s");
    std::printf(
        "books (solver %d): injected %.17g (rate x t %.17g) left %.17g stored %.17g, "
        "balance error %.3g\n",
        static_cast<int>(kind), injected, kRate * time, left, stored,
        Metric(r, "fluid_balance_error"));
    EXPECT_NEAR(time, 1e-3, 1e-15);
    EXPECT_NEAR(injected, kRate * time, 1e-12 * injected);
    EXPECT_GT(left, 0.05 * injected);  // the front reached the outlet: both terms are real
    EXPECT_GT(stored, 0.05 * injected);
    EXPECT_NEAR(injected - left, stored, 1e-12 * injected);
    EXPECT_LE(Metric(r, "fluid_balance_error"), 1e-12);
  }
}

StageSpec StepsStage(std::string name, std::uint64_t steps) {
  StageSpec stage;
  stage.name = std::move(name);
  stage.end = {StepsEnd{steps}};
  return stage;
}

StageRegionSpec RegionValue(std::uint32_t region, SettingSpec value) {
  return StageRegionSpec{region, value};
}

// Backward Euler at 1e4 dt_crit: the slowest mode of these lattices decays by 1/(1 + lambda dt)
// < 1e-2 per step (lambda = pi^2 c / L^2), so 12 steps end a stage steady to far below 1e-12.
SceneSpec Staged(SceneSpec s) {
  s.solver.kind = SolverKind::kImplicit;
  s.solver.dt_factor = 1e4;
  s.solver.end_time_s = 0.0;
  return s;
}

// (5) A stage that changes a region's pressure: the steady flow at the end of each stage is the
// lattice's conductance times that stage's pressure difference.
TEST(BoundaryRegions, StagesChangeARegionsPressureAndTheFlowFollows) {
  constexpr std::uint32_t kColumns = 20, kRows = 6;
  SceneSpec s = Staged(EndRegionsLattice(kColumns, kRows, 1e5, 0.0));
  s.stages = {StepsStage("first", 12), StepsStage("raise", 12), StepsStage("reverse", 12)};
  s.stages[1].regions = {RegionValue(0, 3e5)};
  s.stages[2].regions = {RegionValue(0, -5e4), RegionValue(1, 2.5e4)};
  ASSERT_TRUE(ValidateScene(s).ok()) << ValidateScene(s).message();
  const RunReport r = MustRun(s);
  const double per_pa = (kRows - 1) * LatticePipeConductance() / (kColumns - 2);
  const double drops[] = {1e5, 3e5, -7.5e4};
  for (int k = 1; k <= 3; ++k) {
    const double q = Metric(r, "stage" + std::to_string(k) + "_region_right_flow_m2_per_s");
    std::printf("stage %d: Q = %.17g, analytic %.17g\n", k, q, per_pa * drops[k - 1]);
    EXPECT_NEAR(q, per_pa * drops[k - 1], 1e-9 * per_pa * 3e5);
  }
  EXPECT_EQ(Metric(r, "stages_ended"), 3.0);
}

// (5b) A stage that changes a flux region's rate (at its start, then along a schedule held at its
// last value): the steady outflow is the rate of the moment; resumed mid-stage, the run ends
// bit-identical (the restore re-applies the region's rate of that moment).
TEST(BoundaryRegions, StagesChangeAFluxRegionsRate) {
  SceneSpec s = Staged(FluxToOutletLattice(SolverKind::kImplicit));
  s.stages = {StepsStage("first", 12), StepsStage("double", 12), StepsStage("ramp", 24)};
  s.stages[1].regions = {RegionValue(0, 2.0 * kRate)};
  const double dt = [&] {
    Result<Simulation> probe = Simulation::Create(s);
    EXPECT_TRUE(probe.ok()) << probe.status().message();
    return probe.ok() ? Metric(probe->Report(), "dt_s") : 0.0;
  }();
  ASSERT_GT(dt, 0.0);
  s.stages[2].regions = {RegionValue(0, ScheduleSpec{{0.0, 6.0 * dt}, {2.0 * kRate, -kRate}})};
  const RunReport r = MustRun(s);
  const double rates[] = {kRate, 2.0 * kRate, -kRate};
  for (int k = 1; k <= 3; ++k) {
    const std::string stage = "stage" + std::to_string(k);
    EXPECT_NEAR(Metric(r, stage + "_region_source_flow_m2_per_s"), rates[k - 1], 1e-15 * kRate);
    EXPECT_NEAR(Metric(r, stage + "_region_outlet_flow_m2_per_s"), rates[k - 1], 1e-9 * kRate);
  }

  Result<Simulation> first = Simulation::Create(s);
  ASSERT_TRUE(first.ok());
  std::stop_source stop;
  RunControl control;
  control.stop = stop.get_token();
  control.at_step_end = [&](const Simulation& sim) {
    if (sim.step() == 27) stop.request_stop();  // in the ramp, between two schedule points
  };
  EXPECT_EQ(first->Run(control).code(), StatusCode::kCancelled);
  Result<Simulation> resumed = Simulation::Create(s);
  ASSERT_TRUE(resumed.ok());
  ASSERT_TRUE(resumed->Restore(first->TakeSnapshot()).ok());
  ASSERT_TRUE(resumed->Run({}).ok());
  const RunReport again = resumed->Report();
  for (const char* name : {"region_outlet_flow_m2_per_s", "fluid_injected_m2", "max_pressure_pa",
                           "stage3_region_outlet_flow_m2_per_s"}) {
    EXPECT_EQ(Metric(again, name), Metric(r, name)) << name;
  }
}

// The hydraulic-fracturing sample of the coupled tests (a hex lattice confined by four servo walls
// drained at 0 Pa, the fluid scaled soft so that the DEM step is the contacts'), without bonds,
// well or injection: a flux region injects into its middle instead and a pressure region at 0 Pa
// drains a corner. The fluid pushes the particles apart, so contacts open and the domains are
// re-detected.
SceneSpec MovingLatticeWithRegions() {
  SceneSpec s = effects_test::HydrofracScene(1e5, 1e6);
  s.name = "moving regions";
  s.packing.source = LatticePackingSpec{LatticeKind::kHex, 16, 18, kRadius};
  s.boundary.radial.reset();
  s.boundary.walls_only = true;
  s.solver.end_time_s = 4e-3;
  std::erase_if(s.effects, [](const EffectSpec& e) {
    return std::holds_alternative<BondsEffectSpec>(e) ||
           std::holds_alternative<InjectionEffectSpec>(e);
  });
  const double cx = 17.0 * kRadius, cy = (2.0 + std::sqrt(3.0) * 17.0) * kRadius / 2.0;
  s.boundary.regions = {
      Region("inject", CircleShape{cx, cy, 2.5 * kRadius}, FixedFlux{2e-4}),
      Region("drain", BoxShape{0.0, 0.0, 6.0 * kRadius, 6.0 * kRadius}, FixedPressure{0.0})};
  return s;
}

// Moving particles: the regions are re-applied at every re-detection and the books close.
TEST(BoundaryRegions, MovingParticlesKeepTheirRegionsAndTheBooksClose) {
  const SceneSpec s = MovingLatticeWithRegions();
  ASSERT_TRUE(ValidateScene(s).ok()) << ValidateScene(s).message();
  const RunReport r = MustRun(s);
  const double time = Metric(r, "simulated_time_s");
  const double injected = Metric(r, "fluid_injected_m2");
  std::printf(
      "moving: %g re-detections, injected %.17g (rate x t %.17g), left into the drain "
      "region %.6g, into the walls %.6g, balance error %.3g; %g and %g domains\n",
      Metric(r, "redetections"), injected, 2e-4 * time, Metric(r, "fluid_left_region_drain_m2"),
      Metric(r, "fluid_left_left_wall_m2") + Metric(r, "fluid_left_right_wall_m2") +
          Metric(r, "fluid_left_bottom_wall_m2") + Metric(r, "fluid_left_top_wall_m2"),
      Metric(r, "fluid_balance_error"), Metric(r, "region_inject_domains"),
      Metric(r, "region_drain_domains"));
  EXPECT_GT(Metric(r, "redetections"), 0.0);
  EXPECT_GT(Metric(r, "region_inject_domains"), 0.0);
  EXPECT_GT(Metric(r, "region_drain_domains"), 0.0);
  EXPECT_NEAR(Metric(r, "region_inject_flow_m2_per_s"), 2e-4, 1e-15);
  EXPECT_NEAR(injected, 2e-4 * time, 1e-12 * injected);
  EXPECT_GT(Metric(r, "fluid_left_region_drain_m2"), 0.0);
  EXPECT_LE(Metric(r, "fluid_balance_error"), 1e-12);
}

// A region that holds no domain at set-up is refused naming it; one whose every centroid is a
// boundary node already (here: inside an earlier region) too.
TEST(BoundaryRegions, ARegionWithoutADomainAtSetUpIsNamed) {
  SceneSpec s = EndRegionsLattice(20, 6, 1e5, 0.0);
  s.boundary.regions.push_back(
      Region("outlet", CircleShape{-1.0, -1.0, kRadius}, FixedPressure{0.0}));
  Result<SceneNetwork> net = BuildSceneNetwork(s);
  ASSERT_EQ(net.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(net.status().message().find(
                "scene.boundary.regions[2] ('outlet'): contains no domain centroid"),
            std::string::npos)
      << net.status().message();

  s.boundary.regions.back() =
      Region("inner", BoxShape{0.0, 0.0, 2.5 * kRadius, 1.0}, FixedPressure{1e5});
  net = BuildSceneNetwork(s);
  ASSERT_EQ(net.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(net.status().message().find("scene.boundary.regions[2] ('inner'): its 5 domain "
                                        "centroids belong to the boundary already"),
            std::string::npos)
      << net.status().message();
}

// With a radial boundary the well stays the well's: a region over it takes the domains around
// the well, not the well domain, and the books name the region after the well and the outer ring.
TEST(BoundaryRegions, ARadialBoundaryKeepsItsWellUnderARegion) {
  SceneSpec s = scene_test::LatticeScene(LatticeKind::kHex, 30, 34, FlowAxis::kX);
  s.boundary.radial = RadialBoundarySpec{3.0 * kRadius, 26.0 * kRadius, 1e5, 0.0};
  Result<SceneNetwork> plain = BuildSceneNetwork(s);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  s.boundary.regions = {Region("ring", CircleShape{plain->well_x_m, plain->well_y_m, 8.0 * kRadius},
                               FixedPressure{1e5})};
  Result<SceneNetwork> net = BuildSceneNetwork(s);
  ASSERT_TRUE(net.ok()) << net.status().message();
  ASSERT_GE(net->well_domain, 0);
  const auto& nodes = net->regions[0].nodes;
  EXPECT_EQ(std::count(nodes.begin(), nodes.end(), net->well_domain), 0);
  EXPECT_EQ(net->regions[0].centroids_inside, static_cast<std::int64_t>(nodes.size()) + 1);
  const RunReport r = MustRun(s);
  // The region at the well's pressure moves the sample's inner boundary out to ~8 R: Thiem's
  // rate rises by ln(r_e / r_w) / ln(r_e / 8R) over the plain well's, so it carries the flow and
  // the well (inside it) none.
  EXPECT_EQ(Metric(r, "well_flow_rate_m2_per_s"), 0.0);
  EXPECT_LT(Metric(r, "region_ring_flow_m2_per_s"), 0.0);
  EXPECT_NEAR(-Metric(r, "region_ring_flow_m2_per_s"), Metric(r, "outer_flow_rate_m2_per_s"),
              1e-10 * Metric(r, "outer_flow_rate_m2_per_s"));
}

}  // namespace
}  // namespace seep::core
