// The consolidation-column problem of the coupled grid (see consolidation_problem.h).
#include "consolidation_problem.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "seep/core/reference/terzaghi.h"

namespace seep::bench {
namespace {

using core::SceneSpec;
using core::WallSide;

constexpr std::size_t kBottom = 0, kLeft = 1, kRight = 2, kTop = 3;  // the walls' order
constexpr double kLoadStep = 2e4;                                    // Pa
constexpr double kViscosity = 1.5e-5;        // Pa s: H^2/c_v ~ 50 ms with real water (6 x 24)
constexpr double kPlatenConductance = 1e-2;  // m/(Pa s): the top platen is an ideal drain
constexpr double kServoMaxSpeed = 0.2;       // m/s
constexpr std::array<double, 3> kTimeFactors = {0.05, 0.2, 0.5};
constexpr int kBands = 8;

struct Size {
  std::uint32_t columns, rows;
};
constexpr Size kSizes[] = {{6, 24}, {8, 32}, {10, 40}};

core::WallsEffectSpec Walls(bool drained_base_probe) {
  core::WallsEffectSpec walls;
  if (drained_base_probe) {  // the permeameter: base at 1 kPa, top at 0, no load
    walls.walls = {core::Drained(core::SideWall(WallSide::kBottom), 1e3, kPlatenConductance),
                   core::SideWall(WallSide::kLeft), core::SideWall(WallSide::kRight),
                   core::Drained(core::SideWall(WallSide::kTop), 0.0, kPlatenConductance)};
    return walls;
  }
  walls.walls = {core::SideWall(WallSide::kBottom), core::SideWall(WallSide::kLeft),
                 core::SideWall(WallSide::kRight),
                 core::Drained(core::SideWall(WallSide::kTop, kLoadStep, 0.5, kServoMaxSpeed), 0.0,
                               kPlatenConductance)};
  return walls;
}

SceneSpec Column(const Size& size, double end_time_s) {
  SceneSpec s = WalledLattice(fmt::format("consolidation-{}x{}", size.columns, size.rows),
                              size.columns, size.rows, kViscosity, Walls(false), end_time_s);
  s.fluid.bulk_modulus_pa = kRealWaterBulkModulusPa;
  s.aperture.gap_multiplier = 0.0;
  return s;
}

double Height(const core::LiveState& s) { return s.walls[kTop].py - s.walls[kBottom].py; }

// What the column is, measured on it: E_oed, k and H (NaN when a run fails).
struct ColumnProperties {
  double height = 0.0, oedometer_modulus = 0.0, permeability = 0.0;
};

ColumnProperties Measure(const Size& size) {
  ColumnProperties out;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Drained: the load on the skeleton alone, to rest.
  SceneSpec drained = Column(size, 0.03);
  drained.effects = {SoftLatticeContacts(0.2), Walls(false), core::LocalDampingEffectSpec{0.7}};
  core::Result<core::Simulation> dry = core::Simulation::Create(drained);
  if (!dry.ok()) return {nan, nan, nan};
  out.height = Height(dry->stepper().state());
  const double top0 = dry->stepper().state().walls[kTop].py;
  if (!dry->Run({}).ok()) return {nan, nan, nan};
  out.oedometer_modulus = kLoadStep * out.height / (top0 - dry->stepper().state().walls[kTop].py);
  // k: the walled column at rest between a drained base at 1 kPa and the top platen
  // (platen_permeability_m2, a steady probe solve of the network as it stands).
  SceneSpec probe = Column(size, 1e-6);
  probe.effects = {SoftLatticeContacts(0.5), Walls(true), core::FlowEffectSpec{}};
  core::Result<core::Simulation> flow = core::Simulation::Create(probe);
  if (!flow.ok() || !flow->Run({}).ok()) return {nan, nan, nan};
  out.permeability = ReportMetric(flow->Report(), "platen_permeability_m2");
  return out;
}

core::TerzaghiParameters RealWater(const ColumnProperties& c) {
  core::TerzaghiParameters p;
  p.permeability = c.permeability;
  p.viscosity = kViscosity;
  p.oedometer_modulus = c.oedometer_modulus;
  p.storage_porosity = kLatticeStoragePorosity;
  p.fluid_bulk_modulus = kRealWaterBulkModulusPa;
  p.drainage_length = c.height;
  p.load_step = kLoadStep;
  return p;
}

// What a run shows at one of the time factors: the settlement and the pore-volume weighted pressure
// of depth bands below the top platen.
struct Observation {
  double settlement = 0.0;
  std::array<double, kBands> band{};  // Pa; NaN for a band without pores
};

Observation Observe(const core::LiveState& s, double top0) {
  const double top = s.walls[kTop].py;
  const double height = Height(s);
  std::array<double, kBands> volume{}, pressure{};
  const auto p = s.net.flow.pressure();
  const auto vp = s.net.flow.pore_volume();
  for (std::size_t d = 0; d < s.net.domains.num_domains(); ++d) {
    if (s.net.flow.role()[d] == core::DomainRole::kFixedPressure) continue;
    const double z = top - s.net.domains.centroid_y[d];
    const int band = std::clamp(static_cast<int>(z / height * kBands), 0, kBands - 1);
    volume[band] += vp[d];
    pressure[band] += vp[d] * p[d];
  }
  Observation out;
  out.settlement = top0 - top;
  for (int b = 0; b < kBands; ++b) {
    out.band[b] = volume[b] > 0.0 ? pressure[b] / volume[b] : std::nan("");
  }
  return out;
}

// The series at Tv: settlement and band means (the pores fill a band about evenly; near the
// drained top the isochrone is steep, and its value at the band's mean depth is not its mean).
Observation Series(const core::TerzaghiParameters& real, double t, double tv) {
  constexpr int kPoints = 32;
  Observation out;
  out.settlement = core::Settlement(real, t);
  const double u0 = core::InitialExcessPressure(real);
  for (int b = 0; b < kBands; ++b) {
    double mean = 0.0;
    for (int k = 0; k < kPoints; ++k) {
      mean += core::ExcessPressureRatio((b + (k + 0.5) / kPoints) / kBands, tv) / kPoints;
    }
    out.band[b] = u0 * mean;
  }
  return out;
}

// max(|settlement difference| / final settlement, |band pressure difference| / dsigma).
double Difference(const Observation& a, const Observation& b, double final_settlement) {
  double worst = std::abs(a.settlement - b.settlement) / final_settlement;
  for (int k = 0; k < kBands; ++k) {
    if (std::isfinite(a.band[k]) && std::isfinite(b.band[k])) {
      worst = std::max(worst, std::abs(a.band[k] - b.band[k]) / kLoadStep);
    }
  }
  return worst;
}

}  // namespace

CoupledGrid DefaultConsolidationGrid(bool full) {
  CoupledGrid g;
  g.bulk_moduli = {2.2e9, 2.2e8, 2.2e7, 4e6, 1e6};
  g.flow_every = {4, 16};
  g.dt_safety = {0.5, 0.8};
  g.sizes = full ? 3 : 2;
  g.both_solvers = full;  // explicit sub-cycling at real water costs ~3x the implicit run
  return g;
}

void RunConsolidationGrid(const CoupledGrid& grid, std::vector<AccuracyRun>& rows) {
  std::vector<ColumnProperties> columns;
  for (int i = 0; i < grid.sizes; ++i) columns.push_back(Measure(kSizes[i]));
  const std::size_t first = rows.size();
  std::vector<CoupledChoice> choices = CoupledChoices(grid);
  std::vector<std::vector<Observation>> observed;
  for (const CoupledChoice& choice : choices) {
    const ColumnProperties& column = columns[static_cast<std::size_t>(choice.size)];
    const core::TerzaghiParameters real = RealWater(column);
    const double final_settlement = kLoadStep * column.height / column.oedometer_modulus;
    const double end = 4e-3 + 1.02 * core::TimeForTimeFactor(real, kTimeFactors.back());
    SceneSpec scene = Column(kSizes[choice.size], end);
    ApplyChoice(choice, &scene);
    // The load history's centroid t0 = integral of (1 - sigma(t)/dsigma) dt (trapezoids over the
    // steps), then the error at t0 + t(Tv) for each Tv.
    double t0 = 0.0, last_t = 0.0, last_lag = 1.0, top0 = 0.0;
    bool started = false;
    std::vector<Observation> seen;
    double error = 0.0;
    std::string detail;
    const CoupledRun run = RunCoupled(scene, [&](const core::Simulation& now) {
      const core::LiveState& s = now.stepper().state();
      if (!started) {
        top0 = s.walls[kTop].py;  // one step in: the platen has barely moved
        started = true;
      }
      const double lag = std::max(0.0, 1.0 - s.wall_stress_pa[kTop] / kLoadStep);
      t0 += 0.5 * (lag + last_lag) * (now.time_s() - last_t);
      last_t = now.time_s();
      last_lag = lag;
      if (seen.size() >= kTimeFactors.size()) return true;
      const double tv = kTimeFactors[seen.size()];
      if (now.time_s() < t0 + core::TimeForTimeFactor(real, tv)) return false;
      seen.push_back(Observe(s, top0));
      const double e =
          Difference(seen.back(), Series(real, now.time_s() - t0, tv), final_settlement);
      error = std::max(error, e);
      detail += fmt::format("Tv {:g}: {:.2e}; ", tv, e);
      return seen.size() >= kTimeFactors.size();
    });
    if (seen.size() < kTimeFactors.size()) error = std::numeric_limits<double>::quiet_NaN();
    observed.push_back(seen);
    const int particles = static_cast<int>(kSizes[choice.size].columns * kSizes[choice.size].rows);
    rows.push_back(CoupledRow(
        "consolidation", choice, particles, run, error,
        "max(|s - s_series|/s_final; |u - u_series|/dsigma) at real water's Tv .05/.2/.5",
        detail + fmt::format("E_oed {:.4g} Pa k {:.4g} m2 H {:.4g} m t0 {:.3g} s",
                             column.oedometer_modulus, column.permeability, column.height, t0)));
    PrintCoupledProgress(rows.back(), choice, particles, detail);
  }
  // Against the same column at real water (the base choice at that size): what the choice alone
  // cost, without the lattice's own distance from the series.
  const std::vector<std::size_t> base = RealWaterBaseIndices(choices, grid);
  for (std::size_t i = 0; i < choices.size(); ++i) {
    const std::vector<Observation>& own = observed[i];
    const std::vector<Observation>& real = observed[base[i]];
    const ColumnProperties& column = columns[static_cast<std::size_t>(choices[i].size)];
    const double final_settlement = kLoadStep * column.height / column.oedometer_modulus;
    double worst = own.size() == kTimeFactors.size() && real.size() == kTimeFactors.size()
                       ? 0.0
                       : std::numeric_limits<double>::quiet_NaN();
    for (std::size_t k = 0; std::isfinite(worst) && k < kTimeFactors.size(); ++k) {
      worst = std::max(worst, Difference(own[k], real[k], final_settlement));
    }
    rows[first + i].real_water_error = worst;
  }
}

}  // namespace seep::bench
