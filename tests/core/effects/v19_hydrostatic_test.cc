// V19 (docs/physics.md §5, issue 15): a packing under gravity with no flow in or out. The fluid
// comes to rest at p = rho_f g (h - y) at the domain centroids, nothing flows, and the fluid pushes
// the particles up by rho_f g x their solid area (Archimedes). Also: a sealed column started at one
// pressure relaxes to that state in every transient solver, conserving its fluid.
//
// Parameters unlike the examples: a brine (1180 kg/m^3) in a random column of 0.45-0.6 mm disks,
// 12 x 30 mm, drained at the top only (the base is closed).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <vector>

#include "coupled_scenes.h"
#include "seep/core/coupling/pressure_forces.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/network/fluid_weight.h"
#include "seep/core/network/scene_network.h"

namespace seep::core {
namespace {

using effects_test::MustCreate;
using effects_test::MustRun;

constexpr double kFluidDensity = 1180.0;  // kg/m^3
constexpr double kGravity = -9.81;        // m/s^2, along y

SceneSpec BrineColumn() {
  SceneSpec s;
  s.name = "v19 brine column";
  RandomPackingSpec r;
  r.seed = 19;
  r.width_m = 0.012;
  r.height_m = 0.03;
  r.min_radius_m = 0.45e-3;
  r.max_radius_m = 0.6e-3;
  r.particle_count = 260;
  r.target_porosity = 0.21;
  s.packing.source = r;
  s.packing.contact_gap_m = 2e-5;
  s.fluid.viscosity_pa_s = 1.3e-3;
  s.fluid.bulk_modulus_pa = 2.4e9;
  s.fluid.density_kg_m3 = kFluidDensity;
  s.aperture.residual_aperture_m = 8e-6;
  s.aperture.gap_multiplier = 0.4;
  s.boundary.axis = FlowAxis::kY;
  s.boundary.closed_inlet = true;  // the base is sealed
  s.boundary.outlet_pressure_pa = 0.0;
  s.solver.kind = SolverKind::kSteady;
  s.effects = {GravityEffectSpec{0.0, kGravity}, FlowEffectSpec{}};
  return s;
}

// h: the outlet reservoir's reference point, the mean contact point of its pipes (where the
// scene's outlet pressure applies, network/fluid_weight.h), read from the Darcy bookkeeping.
double OutletElevation(const SceneNetwork& net) {
  double sum = 0.0, count = 0.0;
  for (const ReservoirPipe& e : net.reservoir_pipes) {
    if (e.inlet) continue;
    sum += e.face_m;
    count += 1.0;
  }
  return sum / count;
}

// The largest |p - rho_f g (h - y)| over the domains, relative to the largest such pressure.
double HydrostaticError(const SceneNetwork& net, double h) {
  const auto pressure = net.flow.pressure();
  const double w = -kFluidDensity * kGravity;
  double worst = 0.0, scale = 0.0;
  for (std::size_t d = 0; d < net.domains.num_domains(); ++d) {
    const double exact = w * (h - net.domains.centroid_y[d]);
    worst = std::max(worst, std::abs(pressure[d] - exact));
    scale = std::max(scale, std::abs(exact));
  }
  return worst / scale;
}

// The flow the outlet pipes would carry under the whole column's weight: what "no flow" is
// measured against.
double FlowScale(const SceneNetwork& net, double h) {
  double min_y = h;
  for (const double y : net.domains.centroid_y) min_y = std::min(min_y, y);
  double conductance = 0.0;
  for (const ReservoirPipe& e : net.reservoir_pipes) {
    conductance += net.flow.pipe_conductance()[e.pipe];
  }
  return conductance * (-kFluidDensity * kGravity) * (h - min_y);
}

TEST(Verification, V19_HydrostaticPackingUnderGravity) {
  // Steady: the solve gives the hydrostatic column.
  Simulation steady = MustCreate(BrineColumn());
  MustRun(steady);
  const SceneNetwork& net = steady.network();
  const double h = OutletElevation(net);
  const double error = HydrostaticError(net, h);
  const double outflow = NodeInflow(ComputeBoundaryFluxes(net.flow), net.outlet_node);
  const double scale = FlowScale(net, h);
  std::printf(
      "V19 steady: %zu domains, h = %.6g m, max |p - rho g (h - y)| / p_max = %.3g, "
      "outflow %.3g m^2/s (scale %.3g)\n",
      net.domains.num_domains(), h, error, outflow, scale);
  ASSERT_GT(net.domains.num_domains(), 150u);
  // Exact in the model (the column at rest is an exact solution of the network); 1e-6 leaves
  // the solver's round-off (1e-12) six orders and fails a head term of the wrong sign, length or
  // reference (errors of order 1).
  EXPECT_LT(error, 1e-6);
  EXPECT_LT(std::abs(outflow), 1e-9 * scale);

  // Transient: started at rest (the hydrostatic start about the outlet's reference point), the
  // explicit and the Crank-Nicolson runs stay there.
  for (const SolverKind kind : {SolverKind::kExplicit, SolverKind::kCrankNicolson}) {
    SceneSpec scene = BrineColumn();
    scene.solver.kind = kind;
    scene.solver.storage = StorageVolume::kPore;
    scene.solver.dt_factor = kind == SolverKind::kExplicit ? 0.9 : 20.0;
    scene.solver.end_time_s = 2e-4;
    scene.boundary.initial_pressure_hydrostatic = true;
    scene.boundary.initial_pressure_x_m = 0.0;
    scene.boundary.initial_pressure_y_m = h;
    Simulation run = MustCreate(scene);
    EXPECT_LT(HydrostaticError(run.network(), h), 1e-12);
    MustRun(run);
    const double q = NodeInflow(ComputeBoundaryFluxes(run.network().flow), net.outlet_node);
    EXPECT_LT(HydrostaticError(run.network(), h), 1e-6);
    EXPECT_LT(std::abs(q), 1e-9 * scale);
  }
}

// The fluid force on the particles of the column at rest, through the fluid_forces effect: the
// particles' forces at t = 0 of a coupled scene minus their weight (contact forces cancel in
// the sum, Newton's third law).
TEST(Verification, V19_BuoyancyIsTheWeightOfTheDisplacedFluid) {
  SceneSpec scene = BrineColumn();
  Result<SceneNetwork> built = BuildSceneNetwork(scene);
  ASSERT_TRUE(built.ok()) << built.status().message();
  const double h = OutletElevation(*built);
  ContactsEffectSpec contacts = effects_test::Contacts();
  scene.effects = {contacts, GravityEffectSpec{0.0, kGravity}, FluidForcesEffectSpec{},
                   FlowEffectSpec{}};
  scene.solver.kind = SolverKind::kImplicit;
  scene.solver.storage = StorageVolume::kPore;
  scene.solver.dt_factor = 10.0;
  scene.solver.end_time_s = 1e-4;
  scene.boundary.initial_pressure_hydrostatic = true;
  scene.boundary.initial_pressure_y_m = h;
  Simulation sim = MustCreate(scene);
  const SimulationSnapshot snap = sim.TakeSnapshot();
  ASSERT_TRUE(snap.mechanics);
  const Packing& packing = sim.network().packing;
  double solid = 0.0, total_fx = 0.0, total_fy = 0.0;
  for (std::size_t i = 0; i < packing.size(); ++i) {
    solid += std::numbers::pi * packing.radius[i] * packing.radius[i];
    total_fx += snap.mechanics->fx[i];
    total_fy += snap.mechanics->fy[i];
  }
  const double weight = effects_test::kDensity * kGravity * solid;  // the disks', per m
  const double fluid_fy = total_fy - weight;
  const double archimedes = -kFluidDensity * kGravity * solid;
  // For the record, the rule the head form replaced: the chord rule on each domain's centroid
  // pressure, constant over the face. Its faces' forces close, so its total comes from the outer
  // walk alone (the outline through the hull contact points at the nearest domain's pressure),
  // which tends to n/(1 - n) too much on a sample large against its grains; on this narrow
  // column the boundary terms happen to cancel most of it (printed, not asserted).
  const SceneNetwork& net = sim.network();
  const auto pressure = net.flow.pressure();
  std::vector<double> boundary(net.domains.num_boundary_pipes(),
                               std::numeric_limits<double>::quiet_NaN());
  for (std::size_t p = net.domains.num_pipes(); p < net.pipe_contact.size(); ++p) {
    for (std::size_t k = 0; k < boundary.size(); ++k) {
      if (net.domains.boundary_pipe_contact[k] == net.pipe_contact[p]) {
        boundary[k] = pressure[static_cast<std::size_t>(net.flow.pipe_domain_b()[p])];
      }
    }
  }
  const std::span<const double> domain_pressure = pressure.subspan(0, net.domains.num_domains());
  std::vector<double> arcs;
  OuterArcPressures outer;
  ASSERT_TRUE(outer.Compute(net.domains, domain_pressure, boundary, &arcs).ok());
  std::vector<double> fx(packing.size(), 0.0), fy(packing.size(), 0.0);
  ASSERT_TRUE(AddPressureForces(ViewOf(packing), net.domains, domain_pressure, arcs, fx, fy).ok());
  double old_fy = 0.0;
  for (const double f : fy) old_fy += f;
  std::printf(
      "V19 buoyancy: solid %.6g m^2, rho_f g A_s = %.6g N/m, fluid force (%.3g, %.6g) "
      "N/m; per-domain chord rule gave %.6g N/m (%+.1f %%)\n",
      solid, archimedes, total_fx, fluid_fy, old_fy, 100.0 * (old_fy - archimedes) / archimedes);
  // The issue asks 1 %; the heads' chord rule cancels to the bit at rest and the buoyancy is
  // exact for touching disks, so the figure is round-off of the summed weights (1e-12 of the
  // weight, which is 2.2x the buoyancy): 1e-9 holds with margin.
  EXPECT_NEAR(fluid_fy, archimedes, 1e-9 * std::abs(weight));
  EXPECT_NEAR(total_fx, 0.0, 1e-9 * std::abs(weight));
}

// A sealed column (the outlet pipes removed): started at one pressure, every transient solver
// relaxes it to rest, P_d = p0 + W_d - <W>_Vs (the head uniform, its level fixed by the stored
// fluid), and the stored fluid sum V_s P stays what it was. Gravity tilted, to exercise g.x.
TEST(Verification, SealedColumnRelaxesToHydrostaticConservingFluid) {
  SceneSpec scene = BrineColumn();
  Result<SceneNetwork> built = BuildSceneNetwork(scene);
  ASSERT_TRUE(built.ok()) << built.status().message();
  const SceneNetwork& net = *built;
  const FluidWeight weight{kFluidDensity * 1.7, kFluidDensity * -9.66};
  std::vector<double> node_weight;
  ASSERT_TRUE(ComputeNodeWeightPressures(net, ViewOf(net.packing), weight, &node_weight).ok());

  FlowNetworkData data = net.flow.data();
  const std::size_t domains = net.domains.num_domains();
  FlowNetworkData sealed = data;
  sealed.pipe_domain_a.clear();
  sealed.pipe_domain_b.clear();
  sealed.pipe_length.clear();
  sealed.pipe_aperture.clear();
  sealed.pipe_conductance.clear();
  for (std::size_t p = 0; p < data.pipe_conductance.size(); ++p) {
    if (static_cast<std::size_t>(data.pipe_domain_b[p]) >= domains) continue;
    sealed.pipe_domain_a.push_back(data.pipe_domain_a[p]);
    sealed.pipe_domain_b.push_back(data.pipe_domain_b[p]);
    sealed.pipe_length.push_back(data.pipe_length[p]);
    sealed.pipe_aperture.push_back(data.pipe_aperture[p]);
    sealed.pipe_conductance.push_back(data.pipe_conductance[p]);
  }
  const double p0 = 3.2e3;
  std::fill(sealed.pressure.begin(), sealed.pressure.begin() + static_cast<std::ptrdiff_t>(domains),
            p0);
  Result<FlowNetwork> start = FlowNetwork::Create(sealed);
  ASSERT_TRUE(start.ok()) << start.status().message();
  ASSERT_TRUE(ApplyHeadOffsets(node_weight, &*start).ok());

  const StorageModel storage{StorageVolume::kPore, 1.0, 0.0};
  const double bulk = 2.4e9;
  Result<std::vector<double>> vs = ComputeStorageVolumes(*start, storage);
  ASSERT_TRUE(vs.ok());
  double stored = 0.0, stored_weight = 0.0, volume = 0.0, spread = 0.0;
  for (std::size_t d = 0; d < domains; ++d) {
    stored += (*vs)[d] * p0;
    stored_weight += (*vs)[d] * node_weight[d];
    volume += (*vs)[d];
  }
  const double mean_weight = stored_weight / volume;
  for (std::size_t d = 0; d < domains; ++d) {
    spread = std::max(spread, std::abs(node_weight[d] - mean_weight));
  }
  auto check = [&](const FlowNetwork& network, const char* what) {
    double worst = 0.0, fluid = 0.0;
    for (std::size_t d = 0; d < domains; ++d) {
      worst =
          std::max(worst, std::abs(network.pressure()[d] - (p0 + node_weight[d] - mean_weight)));
      fluid += (*vs)[d] * network.pressure()[d];
    }
    std::printf("%s: max |p - hydrostatic| / spread = %.3g, stored fluid drift %.3g\n", what,
                worst / spread, std::abs(fluid - stored) / stored);
    // At rest to 1e-6 of the column's pressure range (the transients run long enough to damp
    // the slowest mode below 1e-9); the stored fluid to round-off of the sums.
    EXPECT_LT(worst / spread, 1e-6) << what;
    EXPECT_LT(std::abs(fluid - stored) / stored, 1e-12) << what;
  };

  Result<CriticalTimeStep> limit = ComputeCriticalTimeStep(*start, bulk, storage);
  ASSERT_TRUE(limit.ok());
  // The slowest mode decays as exp(-t/tau) with tau ~ L^2/(pi^2 c), about 1e4 x the limit of the
  // smallest domain on this column; 4e5 x the limit damps it below 1e-9 (checked by the test).
  const double duration = 4e5 * limit->dt_crit;
  {
    FlowNetwork network = *start;
    ExplicitSolverOptions options;
    options.bulk_modulus = bulk;
    options.storage = storage;
    Result<ExplicitSolver> solver = ExplicitSolver::Create(options);
    ASSERT_TRUE(solver.ok());
    Result<FlowAdvanceReport> report = solver->Advance(network, duration);
    ASSERT_TRUE(report.ok()) << report.status().message();
    EXPECT_LT(report->max_mass_balance_error, 1e-12);
    check(network, "explicit");
  }
  for (const double theta : {1.0, 0.5}) {
    FlowNetwork network = *start;
    ImplicitSolverOptions options;
    options.bulk_modulus = bulk;
    options.storage = storage;
    options.theta = theta;
    Result<ImplicitSolver> solver = ImplicitSolver::Create(options);
    ASSERT_TRUE(solver.ok());
    // Backward Euler in 400 steps of 1000 x the limit; Crank-Nicolson's stiff modes ring at
    // large steps, so it takes 4000 of 100 x.
    const int steps = theta == 1.0 ? 400 : 4000;
    for (int k = 0; k < steps; ++k) {
      Result<FlowStepReport> report = solver->Step(network, duration / steps);
      ASSERT_TRUE(report.ok()) << report.status().message();
      EXPECT_LT(report->mass_balance_error, 1e-12);
    }
    check(network, theta == 1.0 ? "backward Euler" : "Crank-Nicolson");
  }
  {
    FlowNetwork network = *start;
    SteadyStateOptions options;
    options.storage = storage;
    options.closed_components = ClosedComponentPolicy::kConserveStoredFluid;
    Result<SteadyStateReport> report = SolveSteadyState(network, options);
    ASSERT_TRUE(report.ok()) << report.status().message();
    check(network, "steady");
  }
}

// Bad input: the density and the hydrostatic start name their field; a density without gravity
// and gravity weighing a frozen packing's fluid are valid.
TEST(Verification, FluidWeightInputIsValidated) {
  for (const double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    SceneSpec scene = BrineColumn();
    scene.fluid.density_kg_m3 = bad;
    const Status status = ValidateScene(scene);
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(status.message().rfind("scene.fluid.density_kg_m3: must be a finite number >= 0", 0),
              0u)
        << status.message();
  }
  SceneSpec scene = BrineColumn();
  EXPECT_TRUE(ValidateScene(scene).ok()) << ValidateScene(scene).message();
  scene.effects = {FlowEffectSpec{}};  // a density without gravity: no head term, no error
  EXPECT_TRUE(ValidateScene(scene).ok());
  EXPECT_FALSE(HasFluidWeight(scene));
  scene.boundary.initial_pressure_hydrostatic = true;  // but a hydrostatic start needs weight
  EXPECT_EQ(ValidateScene(scene).message().rfind(
                "scene.boundary.initial_pressure_hydrostatic: needs a fluid with weight", 0),
            0u);
  scene = BrineColumn();
  scene.boundary.initial_pressure_x_m = std::nan("");
  EXPECT_EQ(ValidateScene(scene).message(),
            "scene.boundary.initial_pressure_x_m: must be finite (got nan)");
  scene = BrineColumn();
  scene.fluid.density_kg_m3 = 0.0;  // gravity on a frozen packing weighs nothing without density
  EXPECT_EQ(ValidateScene(scene).message().rfind(
                "scene.effects[0].gravity: requires the contacts effect", 0),
            0u);
}

// A drained platen's head: the platen's reservoir holds its pressure at the platen, so its weight
// pressure is w.x at the wall (network/fluid_weight.h), not 0. A box of walls whose top is a
// platen drained at 12 kPa, started hydrostatic about the platen's height, is at rest: nothing
// flows through the platen (with the platen's weight taken as 0, the brine column's weight would
// drive its pipes at rho g h_platen, of order the scale).
TEST(Verification, DrainedPlatenHoldsTheColumnAtRest) {
  SceneSpec scene = effects_test::BoxedLatticeScene(8, 14);
  scene.fluid.density_kg_m3 = kFluidDensity;
  auto* walls = std::get_if<WallsEffectSpec>(&scene.effects[1]);
  ASSERT_NE(walls, nullptr);
  walls->walls = {SideWall(WallSide::kBottom), SideWall(WallSide::kLeft),
                  SideWall(WallSide::kRight),
                  Drained(SideWall(WallSide::kTop), 1.2e4, effects_test::kPlatenConductance)};
  for (EffectSpec& e : scene.effects) {
    if (auto* g = std::get_if<GravityEffectSpec>(&e)) *g = GravityEffectSpec{0.0, kGravity};
  }
  const double platen_y = MustCreate(scene).stepper().state().walls[3].py;
  scene.boundary.initial_pressure_pa = 1.2e4;
  scene.boundary.initial_pressure_hydrostatic = true;
  scene.boundary.initial_pressure_x_m = 0.0;
  scene.boundary.initial_pressure_y_m = platen_y;
  Simulation sim = MustCreate(scene);
  const SceneNetwork& net = sim.network();
  ASSERT_EQ(net.wall_node.size(), 4u);
  const std::int32_t platen = net.wall_node[3];
  ASSERT_GE(platen, 0);
  double conductance = 0.0;
  const auto a = net.flow.pipe_domain_a();
  const auto b = net.flow.pipe_domain_b();
  for (std::size_t p = 0; p < net.flow.num_pipes(); ++p) {
    if (a[p] == platen || b[p] == platen) conductance += net.flow.pipe_conductance()[p];
  }
  ASSERT_GT(conductance, 0.0);
  const double column = -kFluidDensity * kGravity * platen_y;  // the weight of the whole height
  const double q = NodeInflow(ComputeBoundaryFluxes(net.flow), platen);
  std::printf("drained platen at y = %.6g m: flow %.3g m^2/s against a scale of %.3g\n", platen_y,
              q, conductance * column);
  EXPECT_LT(std::abs(q), 1e-9 * conductance * column);
}

}  // namespace
}  // namespace seep::core
