// The hydraulic-fracturing breakdown problem of the coupled grid (see breakdown_problem.h).
#include "breakdown_problem.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>

namespace seep::bench {
namespace {

using core::SceneSpec;

constexpr double kRadius = 1e-3;          // m
constexpr double kConfinement = 1e5;      // Pa, all four walls
constexpr double kBondStrength = 1e5;     // Pa, tensile (shear twice that)
constexpr double kSolidDensity = 2650.0;  // kg/m^3
// The hex lattice's solid fraction pi / (2 sqrt 3) (the 2 um gaps change it by 0.2 %).
constexpr double kSolidFraction = 0.9069;
// The cap on a run's time at 2e-5 m^2/s (scaled by 2e-5 / rate): at K_f = 2.2e6 the first bond
// breaks at ~0.09 s, and the fluid's storage scales that by 2.2e6 / K_f; the skeleton's
// compliance leaves ~1.4 ms at real water.
constexpr double kCapAtScaledWater = 0.2;     // s at K_f = 2.2e6
constexpr double kCapSkeleton = 4e-3;         // s
constexpr double kCapRate = 2e-5;             // m^2/s
constexpr double kPlatenConductance = 1e-10;  // m/(Pa s), each drained wall stretch

struct Size {
  std::uint32_t columns, rows;
};
constexpr Size kSizes[] = {{24, 28}, {34, 40}};

SceneSpec Sample(const Size& size, double injection_rate) {
  SceneSpec s;
  s.name = fmt::format("breakdown-{}x{}", size.columns, size.rows);
  s.packing.source =
      core::LatticePackingSpec{core::LatticeKind::kHex, size.columns, size.rows, kRadius};
  s.packing.contact_gap_m = 2e-6;
  s.fluid.viscosity_pa_s = 1e-3;
  s.aperture.residual_aperture_m = 1e-6;
  s.aperture.reference_force_n = 1e2;
  s.aperture.gap_multiplier = 1.0;
  s.aperture.max_aperture_m = 1e-4;
  s.boundary.radial = core::RadialBoundarySpec{2.5 * kRadius, 1.0, 0.0, 0.0};
  s.solver.storage = core::StorageVolume::kPore;
  core::ContactsEffectSpec contacts;
  contacts.law.kn = 1e8;
  contacts.law.kt = 5e7;
  contacts.law.friction = 0.5;
  contacts.law.damping_mode = core::NormalDampingMode::kCriticalRatio;
  contacts.law.damping_ratio = 0.3;
  contacts.density_kg_m3 = kSolidDensity;
  core::BondsEffectSpec bonds;
  bonds.params = {1e11, 5e10, 1.0, kBondStrength, 2.0 * kBondStrength};
  bonds.tolerance_m = 1e-6;
  core::WallsEffectSpec walls;
  for (const core::WallSide side : {core::WallSide::kLeft, core::WallSide::kRight,
                                    core::WallSide::kBottom, core::WallSide::kTop}) {
    walls.walls.push_back(
        core::Drained(core::SideWall(side, kConfinement, 0.5, 0.02), 0.0, kPlatenConductance));
  }
  s.effects = {contacts,
               bonds,
               walls,
               core::LocalDampingEffectSpec{0.3},
               core::FlowEffectSpec{},
               core::FluidForcesEffectSpec{},
               core::VolumeChangeEffectSpec{},
               core::ApertureUpdateEffectSpec{},
               core::RedetectionEffectSpec{},
               core::InjectionEffectSpec{injection_rate}};
  return s;
}

// One run to the first break: the row (error unset) and the initiation pressure (NaN without a
// break).
std::pair<AccuracyRun, double> RunToFirstBreak(const std::string& problem,
                                               const CoupledChoice& choice, double rate) {
  const Size& size = kSizes[choice.size];
  SceneSpec scene = Sample(size, rate);
  ApplyChoice(choice, &scene);
  scene.solver.end_time_s =
      (kCapAtScaledWater * 2.2e6 / choice.bulk_modulus_pa + kCapSkeleton) * kCapRate / rate;
  // The well pressure at the last step with every bond intact: the pressure that broke the
  // first one.
  double intact = std::numeric_limits<double>::quiet_NaN(), broke_at = intact;
  const CoupledRun run = RunCoupled(scene, [&](const core::Simulation& now) {
    const core::LiveState& s = now.stepper().state();
    if (s.counters.dem.bonds_broken > 0) {
      broke_at = now.time_s();
      return true;
    }
    if (s.net.well_domain >= 0) {
      intact = s.net.flow.pressure()[static_cast<std::size_t>(s.net.well_domain)];
    }
    return false;
  });
  if (std::isnan(broke_at)) intact = std::numeric_limits<double>::quiet_NaN();
  const int particles = static_cast<int>(size.columns * size.rows);
  const double hubbert_willis = 2.0 * kConfinement + kBondStrength;
  AccuracyRun row = CoupledRow(problem, choice, particles, run, 0.0,
                               "|P_i - P_i(real water)|/P_i(real water)", "");
  double crossing = std::numeric_limits<double>::quiet_NaN();
  if (run.simulation) {
    const double bulk = ReportMetric(run.simulation->Report(), "coupling_skeleton_bulk_modulus_pa");
    crossing = 2.0 * kRadius * size.columns / std::sqrt(bulk / (kSolidDensity * kSolidFraction));
  }
  if (row.note.empty() && std::isnan(broke_at)) {
    row.note =
        fmt::format("rate {:g} m2/s: no bond broke within {:.3g} s", rate, scene.solver.end_time_s);
  } else if (row.note.empty()) {
    row.note = fmt::format(
        "rate {:g} m2/s: P_i {:.4g} Pa ({:+.1f} % of Hubbert-Willis 2 sigma + T) at {:.3g} s = "
        "{:.3g} t_w (t_w {:.3g} s)",
        rate, intact, 100.0 * (intact / hubbert_willis - 1.0), broke_at, broke_at / crossing,
        crossing);
  }
  PrintCoupledProgress(row, choice, particles, row.note, /*error_known=*/false);
  return {row, intact};
}

// error = |P_i - reference| / reference: NaN when either run broke no bond, which a failed run
// never did (a run stops, status OK, at its first break).
void SetError(AccuracyRun* row, double initiation, double reference) {
  row->error = std::abs(initiation - reference) / reference;
  row->real_water_error = row->error;
}

}  // namespace

std::vector<BreakdownGrid> DefaultBreakdownGrids(bool full) {
  CoupledGrid g;
  g.flow_every = {4, 16};
  g.dt_safety = {0.2, 0.3, 0.4, 0.5};  // 0.2: the contacts' default
  g.sizes = full ? 2 : 1;
  // Explicit sub-cycling alone: the implicit solve gives the same initiation pressure (3.873e5
  // against 3.869e5 Pa at real water, equal at 1e9) at 7-12x the time, as it refactors after
  // every re-detection.
  g.base_solver = core::SolverKind::kExplicit;
  g.both_solvers = false;
  CoupledGrid fast = g, slow = g;
  fast.bulk_moduli = {2.2e9, 1e9, 4.4e8, 2.2e8, 2.2e7, 2.2e6, 1e6};
  // The slow rate takes 8x the time to the first break: below 2.2e7 that is > 0.5 s of DEM steps.
  slow.bulk_moduli = {2.2e9, 1e9, 4.4e8, 2.2e8, 2.2e7};
  return {{"breakdown", 2e-5, fast}, {"breakdown-slow", 2.5e-6, slow}};
}

void RunBreakdownGrid(const BreakdownGrid& breakdown, std::vector<AccuracyRun>& rows) {
  const std::size_t first = rows.size();
  const std::vector<CoupledChoice> choices = CoupledChoices(breakdown.grid);
  std::vector<double> initiation;
  for (const CoupledChoice& choice : choices) {
    auto [row, pressure] =
        RunToFirstBreak(breakdown.problem, choice, breakdown.injection_rate_m2_s);
    rows.push_back(std::move(row));
    initiation.push_back(pressure);
  }
  // The error is against real water at the same size: known once that run has been.
  const std::vector<std::size_t> base = RealWaterBaseIndices(choices, breakdown.grid);
  for (std::size_t i = 0; i < choices.size(); ++i) {
    SetError(&rows[first + i], initiation[i], initiation[base[i]]);
  }
}

void RunBreakdownRates(std::vector<AccuracyRun>& rows) {
  const CoupledGrid grid = DefaultBreakdownGrids(false).front().grid;
  const CoupledChoice base = CoupledChoices(grid).front();  // real water, explicit, automatic
  const std::size_t first = rows.size();
  std::vector<double> initiation;
  for (const double rate : {2e-5, 1e-5, 5e-6, 2.5e-6, 1.25e-6}) {
    auto [row, pressure] = RunToFirstBreak("breakdown-rate", base, rate);
    rows.push_back(std::move(row));
    initiation.push_back(pressure);
  }
  for (std::size_t i = 0; i < initiation.size(); ++i) {
    SetError(&rows[first + i], initiation[i], initiation.back());
  }
}

}  // namespace seep::bench
