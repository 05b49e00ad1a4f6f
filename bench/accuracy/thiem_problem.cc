// The radial (Thiem) grid (see thiem_problem.h).
#include "thiem_problem.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "problem_constants.h"
#include "seep/core/reference/analytic_solutions.h"
#include "seep/core/reference/radial_profile.h"
#include "timed_scene.h"

namespace seep::bench {
namespace {

using core::SceneSpec;
using core::SolverKind;
using core::StorageVolume;

constexpr double kWellPressure = 1e5;
constexpr double kWellRadiusInR = 5.0;

SceneSpec RadialScene(int outer_in_r) {
  // Enough columns and rows (6 spare) that the annulus lies inside the lattice, as in V12.
  const auto columns = static_cast<std::uint32_t>(outer_in_r + 6);
  const auto rows = static_cast<std::uint32_t>(std::ceil(2.0 * outer_in_r / std::sqrt(3.0)) + 6);
  SceneSpec s;
  s.name = fmt::format("thiem-hex-{}", outer_in_r);
  s.packing.source = core::LatticePackingSpec{core::LatticeKind::kHex, columns, rows, kRadius};
  s.fluid.viscosity_pa_s = kViscosity;
  s.fluid.bulk_modulus_pa = kBulkModulus;
  s.aperture.residual_aperture_m = kAperture;
  s.boundary.radial =
      core::RadialBoundarySpec{kWellRadiusInR * kRadius, outer_in_r * kRadius, kWellPressure, 0.0};
  s.solver.progress_every = std::numeric_limits<std::uint32_t>::max();
  return s;
}

struct ThiemErrors {
  double ring = 0.0;
  double rate = 0.0;
  double r_w_eff = 0.0;
  std::int64_t domains = 0;
};

double Metric(const core::RunReport& report, const std::string& name) {
  for (const auto& [key, value] : report.metrics) {
    if (key == name) return value;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// The comparison of verification_thiem_test.cc: least-squares p = A + B ln r over the window,
// r_w,eff where the fit reaches p_w, then ring means and the rate against Thiem.
ThiemErrors CompareWithThiem(const core::Simulation& sim) {
  const core::SceneNetwork& net = sim.network();
  const double k = kAperture * kAperture * kAperture / (24.0 * std::sqrt(3.0) * kRadius);
  const core::RunReport report = sim.Report();
  const double q = Metric(report, "well_flow_rate_m2_per_s");
  const double r_e = net.outer_reservoir_radius_m;
  const double r_min = 3.0 * net.mean_radius_m + kWellRadiusInR * kRadius;
  const double r_max = 0.8 * r_e;
  ThiemErrors out;
  out.domains = static_cast<std::int64_t>(net.domains.num_domains()) - 1;
  const auto fit = core::FitRadialProfile(net, r_min, r_max);
  if (!fit.ok()) {
    out.ring = out.rate = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  out.r_w_eff = fit->EffectiveWellRadius(kWellPressure);
  for (const core::RingMean& ring : core::RingMeans(*fit, r_min, r_max, 2.0 * net.mean_radius_m)) {
    const double exact =
        core::ThiemPressure(std::exp(ring.ln_r), out.r_w_eff, r_e, kWellPressure, 0.0);
    out.ring = std::max(out.ring, std::abs(ring.pressure - exact) / kWellPressure);
  }
  const double q_thiem = core::ThiemFlowRate(k, kViscosity, out.r_w_eff, r_e, kWellPressure, 0.0);
  out.rate = std::abs(q - q_thiem) / q_thiem;
  return out;
}

void RunOne(const SceneSpec& scene, int outer_in_r, std::vector<AccuracyRun>& rows) {
  AccuracyRun row;
  row.problem = "thiem";
  row.solver = SolverLabel(scene.solver.kind);
  row.storage = StorageLabel(scene.solver);
  row.dt_over_dt_crit = scene.solver.kind == SolverKind::kSteady ? 0.0 : scene.solver.dt_factor;
  row.resolution = outer_in_r / 2;  // domains (cell widths 2R) across the radius
  row.bulk_modulus_pa = scene.solver.kind == SolverKind::kSteady ? 0.0 : kBulkModulus;
  row.error_kind = "max ring-mean |p - p_Thiem| / dp";
  const auto timed = RunTimed(scene);
  if (!timed.ok()) {
    row.error = std::numeric_limits<double>::quiet_NaN();
    row.note = timed.status().ToString();
    rows.push_back(row);
    return;
  }
  const ThiemErrors e = CompareWithThiem(*timed->simulation);
  row.domains = e.domains;
  row.steps = timed->simulation->step();
  row.wall_s = timed->wall_s;
  row.setup_s = timed->setup_s;
  row.error = e.ring;
  row.note = fmt::format("Q error {:.2e}; r_w_eff {:.3f} R", e.rate, e.r_w_eff / kRadius);
  rows.push_back(row);
}

}  // namespace

ThiemGrid DefaultThiemGrid(bool full) {
  ThiemGrid g;
  g.outer_radii_in_r = {16, 32, 64};
  g.transient_radii_in_r = {16, 32};
  if (full) g.outer_radii_in_r.push_back(128);
  g.implicit_dt_factors = {100, 1000, 10000};
  return g;
}

void RunThiemGrid(const ThiemGrid& grid, std::vector<AccuracyRun>& rows) {
  for (const int outer : grid.outer_radii_in_r) {
    SceneSpec steady = RadialScene(outer);
    steady.solver.kind = SolverKind::kSteady;
    RunOne(steady, outer, rows);
    if (std::find(grid.transient_radii_in_r.begin(), grid.transient_radii_in_r.end(), outer) !=
        grid.transient_radii_in_r.end()) {
      // c = k K_f / (mu n_s) with n_s the hex lattice's pore fraction (sqrt3 - pi/2) / sqrt3.
      const double k = kAperture * kAperture * kAperture / (24.0 * std::sqrt(3.0) * kRadius);
      const double n_s = (std::sqrt(3.0) - std::acos(-1.0) / 2.0) / std::sqrt(3.0);
      const double c = k * kBulkModulus / (kViscosity * n_s);
      const double r_e = outer * kRadius;
      for (const double f : grid.implicit_dt_factors) {
        SceneSpec scene = RadialScene(outer);
        scene.solver.kind = SolverKind::kImplicit;
        scene.solver.storage = StorageVolume::kPore;
        scene.solver.dt_factor = f;
        scene.solver.end_time_s = grid.end_T * r_e * r_e / c;
        RunOne(scene, outer, rows);
      }
    }
    std::fprintf(stderr, "thiem: r_e = %d R done\n", outer);
  }
}

}  // namespace seep::bench
