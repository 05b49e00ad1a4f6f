// The 1D diffusion grid (see diffusion_problem.h).
#include "diffusion_problem.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>

#include "problem_constants.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/reference/analytic_solutions.h"
#include "timed_scene.h"

namespace seep::bench {
namespace {

using core::SceneSpec;
using core::SolverKind;
using core::StorageVolume;

constexpr double kInletPressure = 1e5;
// 4 domains across: interior domains have 4 pipes as in a 2D packing, so dt_crit is that of a
// real lattice (a 1-domain-wide chain would have 2 pipes and twice the critical step).
constexpr std::uint32_t kStripRows = 5;
constexpr double kProbes[] = {0.25, 0.5, 0.75};

SceneSpec StripScene(int cells, double bulk_modulus) {
  SceneSpec s;
  s.name = fmt::format("diffusion-strip-{}", cells);
  s.packing.source = core::LatticePackingSpec{
      core::LatticeKind::kSquare, static_cast<std::uint32_t>(cells), kStripRows, kRadius};
  s.fluid.viscosity_pa_s = kViscosity;
  s.fluid.bulk_modulus_pa = bulk_modulus;
  s.aperture.residual_aperture_m = kAperture;
  s.boundary.axis = core::FlowAxis::kX;
  s.boundary.inlet_pressure_pa = kInletPressure;
  s.boundary.outlet_pressure_pa = 0.0;
  s.boundary.initial_pressure_pa = 0.0;
  // Sample (and report progress) only at the end: the bench times the solver, not the sampling.
  s.solver.progress_every = std::numeric_limits<std::uint32_t>::max();
  return s;
}

// What the error needs from the network: the sample length, where the inlet reservoir sits, the
// 2D porosity and the free domains at the probe positions.
struct StripGeometry {
  double length_m = 0.0;
  double inlet_x_m = 0.0;
  double porosity = 0.0;
  std::int64_t domains = 0;
  std::vector<std::vector<std::size_t>> probe_domains;  // per kProbes entry
};

core::Result<StripGeometry> MeasureStrip(const SceneSpec& scene) {
  SEEP_ASSIGN_OR_RETURN(const core::SceneNetwork net, core::BuildSceneNetwork(scene));
  StripGeometry g;
  g.length_m = net.length_m;
  double image_sum = 0.0;
  double image_count = 0.0;
  for (const core::ReservoirPipe& p : net.reservoir_pipes) {
    if (!p.inlet) continue;
    image_sum += p.image_m;
    image_count += 1.0;
  }
  g.inlet_x_m = image_sum / image_count;
  double pore = 0.0;
  double apparent = 0.0;
  const std::size_t n = net.domains.num_domains();
  for (std::size_t d = 0; d < n; ++d) {
    pore += net.domains.pore_volume[d];
    apparent += net.domains.apparent_volume[d];
  }
  g.porosity = pore / apparent;
  g.domains = static_cast<std::int64_t>(n);
  for (const double xi : kProbes) {
    std::vector<std::size_t> at;
    for (std::size_t d = 0; d < n; ++d) {
      const double x = (net.domains.centroid_x[d] - g.inlet_x_m) / g.length_m;
      if (std::abs(x - xi) < 1e-9) at.push_back(d);
    }
    if (at.empty()) {
      return core::InvalidArgument(
          fmt::format("diffusion strip of {} cells: no domain at x/L = {} (cells must be a "
                      "multiple of 4)",
                      scene.name, xi));
    }
    g.probe_domains.push_back(std::move(at));
  }
  return g;
}

double ProbeError(std::span<const double> p, const StripGeometry& g, double T) {
  double worst = 0.0;
  for (std::size_t k = 0; k < g.probe_domains.size(); ++k) {
    const double exact = core::DiffusionDirichletDirichlet(kProbes[k], T);
    for (const std::size_t d : g.probe_domains[k]) {
      worst = std::max(worst, std::abs(p[d] / kInletPressure - exact));
    }
  }
  return worst;
}

// A backward-Euler or Crank–Nicolson step (right-hand side, CHOLMOD back-substitution, diagnostics)
// costs about ten explicit steps on these strips (this bench measured ~170 against ~16 ns per free
// domain and step at 1276 domains); the weight 25 errs towards skipping, and only skips runs far
// off the front.
constexpr double kImplicitStepCostInExplicitSteps = 25.0;

// The cost of a run in explicit free-domain steps, from the step count the Simulation would take
// (its Create is cheap next to a run this estimate would skip).
double ExpectedCost(const SceneSpec& scene, std::int64_t domains) {
  const auto sim = core::Simulation::Create(scene);
  if (!sim.ok()) return 0.0;  // let the run itself report the error
  const double weight =
      scene.solver.kind == SolverKind::kExplicit ? 1.0 : kImplicitStepCostInExplicitSteps;
  return weight * static_cast<double>(sim->total_steps()) * static_cast<double>(domains);
}

}  // namespace

std::string DiffusionProblemName(double T) { return fmt::format("diffusion_T{}", T); }

DiffusionGrid DefaultDiffusionGrid(bool full) {
  DiffusionGrid g;
  g.times = {0.05, 0.2};
  g.cells = {8, 12, 20, 40, 80, 160, 320};
  if (full) {
    g.cells.push_back(640);
    g.max_cost = 2e9;
  }
  g.bulk_moduli_pa = {2.2e9, 2.2e8, 2.2e7};
  g.explicit_dt_factors = {0.99, 0.9, 0.5, 0.25};
  g.implicit_dt_factors = {1, 3, 10, 30, 100, 300, 1000, 3000};
  if (full) g.implicit_dt_factors.push_back(10000);
  g.cn_dt_factors = g.implicit_dt_factors;
  for (const double f : {10000.0, 30000.0}) {
    if (std::find(g.cn_dt_factors.begin(), g.cn_dt_factors.end(), f) == g.cn_dt_factors.end()) {
      g.cn_dt_factors.push_back(f);
    }
  }
  return g;
}

void RunDiffusionGrid(const DiffusionGrid& grid, std::vector<AccuracyRun>& rows) {
  const auto choices =
      TransientChoices(grid.explicit_dt_factors, grid.implicit_dt_factors, grid.cn_dt_factors);
  for (const int cells : grid.cells) {
    const auto geometry = MeasureStrip(StripScene(cells, grid.bulk_moduli_pa.front()));
    if (!geometry.ok()) {
      std::fprintf(stderr, "diffusion: %s\n", geometry.status().ToString().c_str());
      continue;
    }
    // Exact lattice permeability a^3 / (24 R) (docs/physics.md §1.3).
    const double k = kAperture * kAperture * kAperture / (24.0 * kRadius);
    for (const double T : grid.times) {
      for (const double kf : grid.bulk_moduli_pa) {
        if (kf != grid.bulk_moduli_pa.front() && cells > grid.kf_scaling_max_cells) continue;
        for (const SolverChoice& choice : choices) {
          const double n_s = choice.storage == StorageVolume::kPore ? geometry->porosity : 1.0;
          const double c = k * kf / (kViscosity * n_s);
          for (const double factor : *choice.factors) {
            SceneSpec scene = StripScene(cells, kf);
            scene.solver.kind = choice.kind;
            scene.solver.storage = choice.storage;
            scene.solver.dt_factor = factor;
            scene.solver.end_time_s = T * geometry->length_m * geometry->length_m / c;
            const std::string label = SolverLabel(choice.kind);
            const bool paper = choice.kind == SolverKind::kExplicit &&
                               choice.storage == StorageVolume::kApparent && factor == 0.9 &&
                               kf == grid.bulk_moduli_pa.front();
            if (!paper && ExpectedCost(scene, geometry->domains) > grid.max_cost) {
              std::fprintf(stderr, "diffusion: skipped %s %s %g dt_crit at %d cells (cost cap)\n",
                           label.c_str(), StorageLabel(scene.solver).c_str(), factor, cells);
              continue;
            }
            AccuracyRun row;
            row.problem = DiffusionProblemName(T);
            row.solver = label;
            row.storage = StorageLabel(scene.solver);
            row.dt_over_dt_crit = factor;
            row.resolution = cells - 1;
            row.domains = geometry->domains;
            row.bulk_modulus_pa = kf;
            row.error_kind = "max|p/p1 - series| at x/L=.25/.5/.75";
            const auto timed = RunTimed(scene);
            if (!timed.ok()) {
              row.error = std::numeric_limits<double>::quiet_NaN();
              row.note = timed.status().ToString();
              rows.push_back(row);
              continue;
            }
            row.steps = timed->simulation->step();
            row.wall_s = timed->wall_s;
            row.setup_s = timed->setup_s;
            row.error = ProbeError(timed->simulation->network().flow.pressure(), *geometry, T);
            rows.push_back(row);
          }
        }
      }
      std::fprintf(stderr, "diffusion: T = %g, %d cells done\n", T, cells);
    }
  }
}

}  // namespace seep::bench
