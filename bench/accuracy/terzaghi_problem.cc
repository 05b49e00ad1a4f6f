// The rigid-skeleton Terzaghi grid (see terzaghi_problem.h).
#include "terzaghi_problem.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <span>

#include "problem_constants.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/reference/terzaghi.h"
#include "timed_scene.h"

namespace seep::bench {
namespace {

using core::SceneSpec;
using core::SolverKind;
using core::StorageVolume;

constexpr double kInitialExcessPressure = 1e5;  // u0, Pa
// As the diffusion strip: 4 domains across, so interior domains have 4 pipes (a real lattice's
// dt_crit). All domains of a column carry the same pressure: a 1D column of cells - 1 domains.
constexpr std::uint32_t kColumnRows = 5;

SceneSpec ColumnScene(int cells) {
  SceneSpec s;
  s.name = fmt::format("terzaghi-strip-{}", cells);
  s.packing.source = core::LatticePackingSpec{
      core::LatticeKind::kSquare, static_cast<std::uint32_t>(cells), kColumnRows, kRadius};
  s.fluid.viscosity_pa_s = kViscosity;
  s.fluid.bulk_modulus_pa = kBulkModulus;
  s.aperture.residual_aperture_m = kAperture;
  s.boundary.axis = core::FlowAxis::kX;
  s.boundary.closed_inlet = true;
  s.boundary.outlet_pressure_pa = 0.0;
  s.boundary.initial_pressure_pa = kInitialExcessPressure;
  s.solver.progress_every = std::numeric_limits<std::uint32_t>::max();
  return s;
}

// What the error needs from the network: the drainage length, the drained end, the porosity and
// the free domains with their depth below the drained end.
struct ColumnGeometry {
  double drainage_length_m = 0.0;  // H
  double outlet_x_m = 0.0;         // the outlet reservoir's effective position (z = 0)
  double porosity = 0.0;
  std::int64_t domains = 0;
  std::vector<std::size_t> free_domains;
  std::vector<double> depth_ratio;  // z / H per free domain
};

core::Result<ColumnGeometry> MeasureColumn(const SceneSpec& scene) {
  SEEP_ASSIGN_OR_RETURN(const core::SceneNetwork net, core::BuildSceneNetwork(scene));
  // The base: the hull contacts of the low end, which the same packing with an open inlet turns
  // into inlet pipes (their face_m).
  SceneSpec open = scene;
  open.boundary.closed_inlet = false;
  SEEP_ASSIGN_OR_RETURN(const core::SceneNetwork open_net, core::BuildSceneNetwork(open));
  double base_sum = 0.0;
  double base_count = 0.0;
  for (const core::ReservoirPipe& p : open_net.reservoir_pipes) {
    if (!p.inlet) continue;
    base_sum += p.face_m;
    base_count += 1.0;
  }
  // The outlet reservoir: conductance-weighted mean of the images, as scene_network.h defines it.
  const std::span<const double> conductance = net.flow.pipe_conductance();
  double outlet_sum = 0.0;
  double outlet_weight = 0.0;
  for (const core::ReservoirPipe& p : net.reservoir_pipes) {
    if (p.inlet) continue;
    outlet_sum += conductance[p.pipe] * p.image_m;
    outlet_weight += conductance[p.pipe];
  }
  if (!(base_count > 0.0) || !(outlet_weight > 0.0)) {
    return core::FailedPrecondition(
        fmt::format("{}: no hull contacts at the base or no outlet pipes", scene.name));
  }
  ColumnGeometry g;
  g.outlet_x_m = outlet_sum / outlet_weight;
  g.drainage_length_m = g.outlet_x_m - base_sum / base_count;
  double pore = 0.0;
  double apparent = 0.0;
  const std::size_t n = net.domains.num_domains();
  for (std::size_t d = 0; d < n; ++d) {
    pore += net.domains.pore_volume[d];
    apparent += net.domains.apparent_volume[d];
    g.free_domains.push_back(d);
    g.depth_ratio.push_back((g.outlet_x_m - net.domains.centroid_x[d]) / g.drainage_length_m);
  }
  g.porosity = pore / apparent;
  g.domains = static_cast<std::int64_t>(n);
  return g;
}

struct ColumnError {
  double profile = 0.0;  // relative L2 of u/u0
  double u_num = 0.0;    // degree of consolidation from the stored fluid
  double u_exact = 0.0;
  // U with the initial content referred to the whole column, H / (N h) times the network's own:
  // the network stores nothing in the half cell between its last domain and the outlet.
  double u_column = 0.0;
};

ColumnError ErrorOf(const core::FlowNetwork& flow, StorageVolume storage, const ColumnGeometry& g,
                    double Tv, double stored_length_m) {
  const std::span<const double> p = flow.pressure();
  const std::span<const double> volume =
      storage == StorageVolume::kPore ? flow.pore_volume() : flow.apparent_volume();
  double diff2 = 0.0;
  double exact2 = 0.0;
  double stored = 0.0;
  double initial = 0.0;
  for (std::size_t k = 0; k < g.free_domains.size(); ++k) {
    const std::size_t d = g.free_domains[k];
    const double exact = core::ExcessPressureRatio(g.depth_ratio[k], Tv);
    const double u = p[d] / kInitialExcessPressure;
    diff2 += (u - exact) * (u - exact);
    exact2 += exact * exact;
    stored += volume[d] * p[d];
    initial += volume[d] * kInitialExcessPressure;
  }
  ColumnError e;
  e.profile = std::sqrt(diff2 / exact2);
  e.u_num = 1.0 - stored / initial;
  e.u_exact = core::DegreeOfConsolidation(Tv);
  e.u_column = 1.0 - (stored / initial) * stored_length_m / g.drainage_length_m;
  return e;
}

}  // namespace

TerzaghiGrid DefaultTerzaghiGrid(bool full) {
  TerzaghiGrid g;
  g.cells = {20, 40, 80, 160};
  if (full) g.cells.push_back(320);
  g.explicit_dt_factors = {0.99, 0.9, 0.5};
  // From 10 dt_crit on: at 1 dt_crit the implicit schemes cost ten explicit runs for nothing.
  g.implicit_dt_factors = {10, 30, 100, 300, 1000};
  g.cn_dt_factors = {10, 30, 100, 300, 1000, 3000};
  return g;
}

void RunTerzaghiGrid(const TerzaghiGrid& grid, std::vector<AccuracyRun>& rows) {
  const auto choices =
      TransientChoices(grid.explicit_dt_factors, grid.implicit_dt_factors, grid.cn_dt_factors);
  // Exact lattice permeability a^3 / (24 R) (docs/physics.md §1.3).
  const double k = kAperture * kAperture * kAperture / (24.0 * kRadius);
  const double Tv = grid.time_factor;
  for (const int cells : grid.cells) {
    const auto geometry = MeasureColumn(ColumnScene(cells));
    if (!geometry.ok()) {
      std::fprintf(stderr, "terzaghi: %s\n", geometry.status().ToString().c_str());
      continue;
    }
    const double H = geometry->drainage_length_m;
    for (const SolverChoice& choice : choices) {
      const double n_s = choice.storage == StorageVolume::kPore ? geometry->porosity : 1.0;
      // m_v = 0: c_v = k / (mu n_s / K_f).
      const double c_v = k * kBulkModulus / (kViscosity * n_s);
      for (const double factor : *choice.factors) {
        SceneSpec scene = ColumnScene(cells);
        scene.solver.kind = choice.kind;
        scene.solver.storage = choice.storage;
        scene.solver.dt_factor = factor;
        scene.solver.end_time_s = Tv * H * H / c_v;
        AccuracyRun row;
        row.problem = "terzaghi";
        row.solver = SolverLabel(choice.kind);
        row.storage = StorageLabel(scene.solver);
        row.dt_over_dt_crit = factor;
        row.resolution = cells - 1;
        row.domains = geometry->domains;
        row.bulk_modulus_pa = kBulkModulus;
        row.error_kind = fmt::format("rel L2 of u/u0 profile at Tv={:g}", Tv);
        const auto timed = RunTimed(scene);
        if (!timed.ok()) {
          row.error = std::numeric_limits<double>::quiet_NaN();
          row.note = timed.status().ToString();
          rows.push_back(row);
          continue;
        }
        // The domains' control volumes span N h = (cells - 1) 2R of the column.
        const ColumnError e = ErrorOf(timed->simulation->network().flow, choice.storage, *geometry,
                                      Tv, (cells - 1) * 2.0 * kRadius);
        row.steps = timed->simulation->step();
        row.wall_s = timed->wall_s;
        row.setup_s = timed->setup_s;
        row.error = e.profile;
        row.note = fmt::format("U_num {:.4f} U(Tv) {:.4f} |dU| {:.2e} |dU_H| {:.2e} H/h {:g}",
                               e.u_num, e.u_exact, std::abs(e.u_num - e.u_exact),
                               std::abs(e.u_column - e.u_exact), H / (2.0 * kRadius));
        rows.push_back(row);
      }
    }
    std::fprintf(stderr, "terzaghi: Tv = %g, %d cells done\n", Tv, cells);
  }
}

}  // namespace seep::bench
