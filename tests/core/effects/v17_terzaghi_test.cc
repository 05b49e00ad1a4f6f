// V17 (docs/physics.md §3.4 and §5): Terzaghi consolidation of a DEM column, after Yade's
// FluidCouplingPFV/oedometer.py, without normalisation. A hex-lattice column between walls that
// bound the fluid (impermeable base and sides, a drained porous top platen) takes a load step of
// total stress on its servo-controlled top platen. The analytic side (terzaghi.h) is fed with
// what the column itself measures: E_oed from a drained DEM load step, k from a steady
// permeameter run on the same packing, n from the walled network's pore and box areas.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/reference/terzaghi.h"
#include "seep/core/run/simulation.h"
#include "terzaghi_column_probe.h"

namespace seep::core {
namespace {

using terzaghi_probe::Isochrone;
using terzaghi_probe::kBottomWall;
using terzaghi_probe::kTopWall;
using terzaghi_probe::LoadCentroid;
using terzaghi_probe::OneThread;
using terzaghi_probe::RunAndSample;
using terzaghi_probe::Sample;
using terzaghi_probe::SettlementAt;
using terzaghi_probe::WindowMean;

// The column: 10 x 40 equal disks on a hex lattice (rows horizontal), H ~ 68 mm. Every contact of
// the lattice touches at set-up and the springs are linear, so the skeleton is (close to) linear
// elastic from zero stress on: no preload is needed for the drained and the undrained response to
// see the same E_oed, and the packing is used as built (no settling, no lost contact history).
constexpr std::uint32_t kColumns = 10;
constexpr std::uint32_t kRows = 40;
constexpr double kDiskRadius = 1e-3;      // m
constexpr double kDensity = 2650.0;       // kg/m^3
constexpr double kNormalStiffness = 1e7;  // N/m per m; E_oed comes out ~1.7 kn
constexpr double kLoadStep = 2e4;         // Pa: strain ~1e-3, pore volumes change by ~1 %
// K_f ~ 1.2 n E_oed: u0/dsigma = m_v/(m_v + n/K_f) ~ 0.56, well inside (0.5, 0.9), so the test
// sees the fluid's compressibility as well as the drainage.
constexpr double kBulkModulus = 2e6;  // Pa
// With a0 = 10 um (k ~ 2.3e-14 m^2) this viscosity puts H^2/c_v at ~52 ms: about 50 crossings of
// the undrained compression wave (~1 ms) and ~1e4 DEM steps.
constexpr double kViscosity = 1.5e-5;       // Pa s
constexpr double kResidualAperture = 1e-5;  // m, every pipe (no aperture update: k is constant)
// The coupled step is set by the fluid's stiffness (~7 kn per disk here): 0.5 of it is ~0.18
// sqrt(m/kn), stable. The drained DEM-only run needs its own, smaller, factor: at 0.5 sqrt(m/kn)
// the walled lattice oscillates.
constexpr double kCoupledDtSafety = 0.5;
constexpr double kDrainedDtSafety = 0.2;
// Local damping damps the loading transient; the consolidation itself is quasi-static (the
// unbalanced forces it acts on are tiny), so it does not slow the settlement measurably. Checked
// without it: the coupled step must drop to dt_safety 0.25 (at 0.5 the undamped column blows up,
// a domain collapses at step ~560), the column still rings in the 4..8 ms undrained window (u0
// +6.5 %), and U from the settlement stays within 0.04 of U(Tv) at Tv = 0.05..1 (with it: 0.064).
constexpr double kLocalDamping = 0.3;
constexpr double kServoMaxSpeed = 0.2;  // m/s: the load is on in ~1 ms, Tv ~ 0.02

// Storage: n V_d (docs/physics.md §1.2 reading (b), solver.storage_factor), the fluid's share of
// the box with dV = the box's change. V_p would make the soft contacts' growing overlaps part of
// the fluid's volume change (a compressible "grain": at this load their lenses take ~16 % of dV),
// which Terzaghi's incompressible grains leave out; n = 0.14 is the walled column's own V_p / V_d.
constexpr double kStoragePorosity = 0.14;
// The top platen: each stretch over a pore passes 1e-2 m^2/s per Pa per m, ~1e4 times a pipe of
// the column, so the platen holds its pores at its 0 Pa like an ideal drain.
constexpr double kPlatenConductance = 1e-2;  // m/(Pa s)

ContactsEffectSpec Contacts(double dt_safety) {
  ContactsEffectSpec c;
  c.law.kn = kNormalStiffness;
  c.law.kt = 0.5 * kNormalStiffness;
  c.law.friction = 0.0;
  c.law.damping_mode = NormalDampingMode::kCriticalRatio;
  c.law.damping_ratio = 0.3;
  c.density_kg_m3 = kDensity;
  c.dt_safety = dt_safety;
  return c;
}

WallsEffectSpec Walls() {
  WallsEffectSpec walls;
  walls.walls = {
      SideWall(WallSide::kBottom), SideWall(WallSide::kLeft), SideWall(WallSide::kRight),
      Drained(SideWall(WallSide::kTop, kLoadStep, 0.5, kServoMaxSpeed), 0.0, kPlatenConductance)};
  return walls;
}

// The coupled load step: the walls bound the fluid (drained top platen at 0 Pa), implicit flow
// (updated every DEM step, since the fluid's stiffness sets that step).
SceneSpec ColumnScene(double viscosity, double end_time_s) {
  SceneSpec s;
  s.name = "v17 terzaghi column";
  s.packing.source = LatticePackingSpec{LatticeKind::kHex, kColumns, kRows, kDiskRadius};
  s.packing.contact_gap_m = 1e-6;
  s.fluid.viscosity_pa_s = viscosity;
  s.fluid.bulk_modulus_pa = kBulkModulus;
  s.aperture.residual_aperture_m = kResidualAperture;
  s.aperture.reference_force_n = 1e3;
  s.aperture.gap_multiplier = 0.0;
  s.boundary.walls_only = true;
  s.boundary.initial_pressure_pa = 0.0;
  s.solver.kind = SolverKind::kImplicit;
  s.solver.storage = StorageVolume::kApparent;
  s.solver.storage_factor = kStoragePorosity;
  s.solver.dt_factor = 1e6;  // the flow interval is then the DEM step
  s.solver.end_time_s = end_time_s;
  // AUTO: the test checks the size-chosen factorization against Terzaghi's solution (supernodal
  // at this column's size, linear_solver_kind.h); every other scene here keeps
  // the default.
  s.solver.linear_solver = LinearSolverKind::kAuto;
  s.effects = {Contacts(kCoupledDtSafety),
               Walls(),
               LocalDampingEffectSpec{kLocalDamping},
               FlowEffectSpec{},
               FluidForcesEffectSpec{},
               VolumeChangeEffectSpec{}};
  return s;
}

double Metric(const RunReport& report, const char* name) {
  for (const auto& [key, value] : report.metrics) {
    if (key == name) return value;
  }
  ADD_FAILURE() << "no metric " << name;
  return 0.0;
}

TEST(V17Terzaghi, ColumnConsolidatesAsTerzaghiPredicts) {
  const OneThread one_thread;

  // 1. E_oed: the same load step drained (DEM only, no fluid), to equilibrium. The fluid fills the
  // box between the walls, so the strain is the platen's settlement over the box height.
  SceneSpec drained = ColumnScene(kViscosity, 0.03);
  drained.effects = {Contacts(kDrainedDtSafety), Walls(), LocalDampingEffectSpec{0.7}};
  Result<Simulation> box = Simulation::Create(drained);
  ASSERT_TRUE(box.ok()) << box.status().message();
  const double height =
      box->stepper().state().walls[kTopWall].py - box->stepper().state().walls[kBottomWall].py;
  const std::vector<Sample> dry = RunAndSample(drained, 100);
  ASSERT_FALSE(HasFailure());
  ASSERT_GT(dry.size(), 4u);
  const Sample& dry_end = dry.back();
  // Equilibrium: the settlement no longer moves over the last quarter of the run.
  const double dry_3q = SettlementAt(dry, 0.75 * dry_end.t);
  ASSERT_NEAR(dry_end.settlement, dry_3q, 1e-4 * dry_end.settlement);
  const double s_final = dry_end.settlement;
  const double e_oed = kLoadStep * height / s_final;

  // 2. k: steady flow between two drained platens through the walled column at rest; the same
  // packing's permeameter without walls (frozen, open ends) for comparison.
  const double k =
      terzaghi_probe::WalledPermeability(ColumnScene(kViscosity, 0.0), kPlatenConductance);
  SceneSpec permeameter = ColumnScene(kViscosity, 0.0);
  permeameter.effects.clear();
  permeameter.solver.kind = SolverKind::kSteady;
  permeameter.boundary.walls_only = false;
  permeameter.boundary.axis = FlowAxis::kY;
  permeameter.boundary.inlet_pressure_pa = 1e3;
  Result<Simulation> steady = Simulation::Create(permeameter);
  ASSERT_TRUE(steady.ok()) << steady.status().message();
  ASSERT_TRUE(steady->Run({}).ok());
  const double k_open = Metric(steady->Report(), "permeability_m2");
  std::printf("V17: k with walls %.4g m^2, without (open-ended permeameter) %.4g m^2\n", k, k_open);
  const double n = kStoragePorosity;

  TerzaghiParameters terzaghi;
  terzaghi.permeability = k;
  terzaghi.viscosity = kViscosity;
  terzaghi.oedometer_modulus = e_oed;
  terzaghi.storage_porosity = n;
  terzaghi.fluid_bulk_modulus = kBulkModulus;
  terzaghi.drainage_length = height;  // impermeable base to drained platen
  terzaghi.load_step = kLoadStep;
  ASSERT_TRUE(ValidateTerzaghiParameters(terzaghi).ok());
  const double c_v = ConsolidationCoefficient(terzaghi);
  // u0 = dsigma (K_f/n) / (K_f/n + E_oed), the form of dsigma m_v / (m_v + n/K_f).
  const double u0 = InitialExcessPressure(terzaghi);
  const double t_consolidation = TimeForTimeFactor(terzaghi, 1.0);
  // The scene must stay in the regime the test is for: a compressible fluid that takes a fair
  // part of the load, and a consolidation far slower than the ~1 ms mechanical response.
  ASSERT_GT(u0 / kLoadStep, 0.4);
  ASSERT_LT(u0 / kLoadStep, 0.9);
  ASSERT_GT(t_consolidation, 0.03);

  // 3. u0 measured: the same coupled load step with a viscosity 1e6 times higher, so that nothing
  // drains (Tv < 1e-6 at its end); the pore-volume weighted mean pressure of the column at rest,
  // averaged over 4..8 ms (the load takes ~1 ms to go on, the column ~2 ms more to settle).
  // u0 measured: the same load step on the column sealed (the platen impermeable too) and with a
  // fluid 20 times thinner, so that the pressure evens out inside it within a few ms (H^2/c_v
  // ~3 ms; the fluid's viscosity does not enter u0). The mean over 4..8 ms.
  SceneSpec sealed = ColumnScene(kViscosity / 20.0, 0.008);
  std::get<WallsEffectSpec>(sealed.effects[1]).walls[kTopWall].drain.reset();
  const std::vector<Sample> undrained = RunAndSample(sealed, 20);
  ASSERT_FALSE(HasFailure());
  const double u0_measured =
      WindowMean(undrained, 0.004, 0.008, [](const Sample& s) { return s.mean_pressure; });

  // 4. The draining load step, to Tv = 1.05, with the isochrones along the way.
  std::vector<Isochrone> isochrones;
  const std::vector<Sample> draining =
      RunAndSample(ColumnScene(kViscosity, 1.05 * t_consolidation), 20, &isochrones);
  ASSERT_FALSE(HasFailure());
  // The servo puts the load on over ~2 ms (Tv ~ 0.03): the instantaneous-load solution holds
  // from the load history's centroid t0 = integral of (1 - sigma(t)/dsigma) dt on.
  const double t0 =
      LoadCentroid(draining, 0.0, std::numeric_limits<double>::infinity(), 0.0, kLoadStep);
  std::printf("V17: load centroid t0 = %.4g s (Tv %.4f)\n", t0, TimeFactor(terzaghi, t0));

  std::printf(
      "V17: E_oed = %.4g Pa, k = %.4g m^2, n = %.4f, K_f = %.3g Pa, mu = %.3g Pa s, "
      "H = %.4g m\n",
      e_oed, k, n, kBulkModulus, kViscosity, height);
  std::printf(
      "V17: c_v = %.4g m^2/s, H^2/c_v = %.4g s, u0 analytic = %.5g Pa (%.4f dsigma), "
      "measured = %.5g Pa (%+.2f %%)\n",
      c_v, t_consolidation, u0, u0 / kLoadStep, u0_measured, 100.0 * (u0_measured / u0 - 1.0));

  // u0 within 3 % of the analytic value, no normalisation.
  EXPECT_NEAR(u0_measured / u0, 1.0, 0.03);

  // Isochrones at Tv = 0.05, 0.2, 0.5 (the samples nearest t0 + t(Tv)) within 0.05 u0 of the
  // Terzaghi series u/u0(z/H, Tv).
  ASSERT_FALSE(isochrones.empty());
  for (const double wanted : {0.05, 0.2, 0.5}) {
    const double t_wanted = t0 + TimeForTimeFactor(terzaghi, wanted);
    const Isochrone& iso = *std::min_element(
        isochrones.begin(), isochrones.end(), [&](const Isochrone& a, const Isochrone& b) {
          return std::abs(a.t - t_wanted) < std::abs(b.t - t_wanted);
        });
    const double tv = TimeFactor(terzaghi, iso.t - t0);
    for (std::size_t b = 0; b < iso.depth.size(); ++b) {
      const double expected = u0 * ExcessPressureRatio(iso.depth[b] / height, tv);
      std::printf("V17: Tv %.3f  z/H %.3f  u/u0 measured %.4f  Terzaghi %.4f\n", tv,
                  iso.depth[b] / height, iso.pressure[b] / u0, expected / u0);
      EXPECT_NEAR(iso.pressure[b], expected, 0.05 * u0)
          << "Tv = " << tv << ", z/H = " << iso.depth[b] / height;
    }
  }

  // U(Tv) within 0.05 from the settlement and the analytic settlements: undrained
  // (dsigma - u0) H / E_oed, final dsigma H / E_oed (= the drained run's).
  const double s_undrained = (kLoadStep - u0) * height / e_oed;
  std::printf("V17:   Tv   U(Tv)  U settlement\n");
  for (const double tv : {0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0}) {
    const double t = TimeForTimeFactor(terzaghi, tv) + t0;
    const double expected = DegreeOfConsolidation(tv);
    const double from_settlement =
        (SettlementAt(draining, t) - s_undrained) / (s_final - s_undrained);
    std::printf("V17: %5.2f  %.4f  %.4f\n", tv, expected, from_settlement);
    EXPECT_NEAR(from_settlement, expected, 0.05) << "Tv = " << tv;
  }
}

// V20 (docs/physics.md §5): undrained loading. A sealed sample (every wall impermeable) squeezed by
// four servo walls at the same total stress: the pore fluid takes the undrained share
//   du/dsigma = (K_f/n) / (K_f/n + K),
// K the 2D bulk modulus of the drained skeleton (dsigma over the area strain of the same load
// step without fluid). Parameters unlike V17's: a squat 14 x 12 lattice, a stiffer fluid, a
// larger load, biaxial instead of oedometric.
TEST(V20UndrainedLoading, SealedSampleTakesTheUndrainedShareOfTheLoad) {
  const OneThread one_thread;
  constexpr double kLoad = 3.5e4;  // Pa, on every wall
  constexpr double kFluid = 4e6;   // Pa
  SceneSpec s;
  s.name = "v20 undrained loading";
  s.packing.source = LatticePackingSpec{LatticeKind::kHex, 14, 12, kDiskRadius};
  s.packing.contact_gap_m = 1e-6;
  s.fluid.viscosity_pa_s = kViscosity / 20.0;  // evens out inside the sample within ~1 ms
  s.fluid.bulk_modulus_pa = kFluid;
  s.aperture.residual_aperture_m = kResidualAperture;
  s.aperture.reference_force_n = 1e3;
  s.boundary.walls_only = true;
  s.solver.kind = SolverKind::kImplicit;
  s.solver.storage = StorageVolume::kApparent;
  s.solver.storage_factor = kStoragePorosity;
  s.solver.dt_factor = 1e6;
  s.solver.end_time_s = 0.03;
  WallsEffectSpec walls;
  for (const WallSide side :
       {WallSide::kBottom, WallSide::kLeft, WallSide::kRight, WallSide::kTop}) {
    walls.walls.push_back(SideWall(side, kLoad, 0.5, kServoMaxSpeed));
  }
  const auto area = [](const LiveState& state) {
    return (state.walls[2].px - state.walls[1].px) * (state.walls[3].py - state.walls[0].py);
  };

  // Drained: the load on the skeleton alone, to rest.
  SceneSpec drained = s;
  drained.effects = {Contacts(kDrainedDtSafety), walls, LocalDampingEffectSpec{0.7}};
  Result<Simulation> dry = Simulation::Create(drained);
  ASSERT_TRUE(dry.ok()) << dry.status().message();
  const double area0 = area(dry->stepper().state());
  ASSERT_TRUE(dry->Run({}).ok());
  const double strain = 1.0 - area(dry->stepper().state()) / area0;
  const double bulk = kLoad / strain;

  // Sealed: the same load with the fluid in.
  SceneSpec sealed = s;
  sealed.solver.end_time_s = 0.008;
  sealed.effects = {Contacts(kCoupledDtSafety),
                    walls,
                    LocalDampingEffectSpec{kLocalDamping},
                    FlowEffectSpec{},
                    FluidForcesEffectSpec{},
                    VolumeChangeEffectSpec{}};
  double sum = 0.0;
  int count = 0;
  Result<Simulation> wet = Simulation::Create(sealed);
  ASSERT_TRUE(wet.ok()) << wet.status().message();
  RunControl control;
  control.at_step_end = [&](const Simulation& now) {
    if (now.time_s() < 0.004) return;
    sum += VolumeWeightedMeanPressure(now.stepper().state().net.flow, StorageVolume::kApparent);
    ++count;
  };
  ASSERT_TRUE(wet->Run(control).ok());
  ASSERT_GT(count, 0);
  const double du = sum / count;
  const double stiffness = kFluid / kStoragePorosity;
  const double expected = stiffness / (stiffness + bulk);
  std::printf(
      "V20: K = %.4g Pa, K_f/n = %.4g Pa, du/dsigma measured %.4f, undrained %.4f (%+.2f %%)\n",
      bulk, stiffness, du / kLoad, expected, 100.0 * (du / kLoad / expected - 1.0));
  EXPECT_NEAR(du / kLoad, expected, 0.03 * expected);
}

}  // namespace
}  // namespace seep::core
