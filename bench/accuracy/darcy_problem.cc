// The Darcy permeability grid (see darcy_problem.h).
#include "darcy_problem.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "problem_constants.h"
#include "timed_scene.h"

namespace seep::bench {
namespace {

using core::SceneSpec;
using core::SolverKind;
using core::StorageVolume;

// Square lattice: pore / apparent volume of every domain, (4 - pi) / 4 (docs/physics.md §1.2).
constexpr double kSquarePorosity = 0.21460183660255172;

SceneSpec LatticeScene(int side) {
  SceneSpec s;
  s.name = fmt::format("darcy-square-{}", side);
  s.packing.source =
      core::LatticePackingSpec{core::LatticeKind::kSquare, static_cast<std::uint32_t>(side),
                               static_cast<std::uint32_t>(side), kRadius};
  s.fluid.viscosity_pa_s = kViscosity;
  s.fluid.bulk_modulus_pa = kBulkModulus;
  s.aperture.residual_aperture_m = kAperture;
  s.boundary.axis = core::FlowAxis::kX;
  s.boundary.inlet_pressure_pa = 1e5;
  s.boundary.outlet_pressure_pa = 0.0;
  s.solver.progress_every = std::numeric_limits<std::uint32_t>::max();
  return s;
}

double Metric(const core::RunReport& report, const std::string& name) {
  for (const auto& [key, value] : report.metrics) {
    if (key == name) return value;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

void RunOne(const SceneSpec& scene, int side, std::vector<AccuracyRun>& rows) {
  AccuracyRun row;
  row.problem = "darcy";
  row.solver = SolverLabel(scene.solver.kind);
  row.storage = StorageLabel(scene.solver);
  row.dt_over_dt_crit = scene.solver.kind == SolverKind::kSteady ? 0.0 : scene.solver.dt_factor;
  row.resolution = side - 1;
  row.domains = static_cast<std::int64_t>(side - 1) * (side - 1);
  row.bulk_modulus_pa = scene.solver.kind == SolverKind::kSteady ? 0.0 : kBulkModulus;
  row.error_kind = "|k - a^3/(24R)| / k";
  const auto timed = RunTimed(scene);
  if (!timed.ok()) {
    row.error = std::numeric_limits<double>::quiet_NaN();
    row.note = timed.status().ToString();
    rows.push_back(row);
    return;
  }
  row.steps = timed->simulation->step();
  row.wall_s = timed->wall_s;
  row.setup_s = timed->setup_s;
  row.error = Metric(timed->simulation->Report(), "permeability_relative_error");
  rows.push_back(row);
}

}  // namespace

DarcyGrid DefaultDarcyGrid(bool full) {
  DarcyGrid g;
  g.sides = {11, 21, 41, 81, 161};
  g.transient_sides = {11, 21, 41};
  if (full) {
    g.sides.push_back(321);
    g.transient_sides.push_back(81);
  }
  g.implicit_dt_factors = {10, 100, 1000, 10000};
  return g;
}

void RunDarcyGrid(const DarcyGrid& grid, std::vector<AccuracyRun>& rows) {
  for (const int side : grid.sides) {
    SceneSpec steady = LatticeScene(side);
    steady.solver.kind = SolverKind::kSteady;
    RunOne(steady, side, rows);
    if (std::find(grid.transient_sides.begin(), grid.transient_sides.end(), side) !=
        grid.transient_sides.end()) {
      // Exact lattice k and the sample length of the square lattice, L = side * 2R (reservoirs on
      // the particles' outer surfaces, see scene_network.h).
      const double k = kAperture * kAperture * kAperture / (24.0 * kRadius);
      const double length = side * 2.0 * kRadius;
      struct Choice {
        SolverKind kind;
        StorageVolume storage;
        double factor;
      };
      std::vector<Choice> choices = {{SolverKind::kExplicit, StorageVolume::kApparent, 0.9},
                                     {SolverKind::kExplicit, StorageVolume::kPore, 0.9}};
      for (const double f : grid.implicit_dt_factors) {
        choices.push_back({SolverKind::kImplicit, StorageVolume::kPore, f});
      }
      for (const Choice& choice : choices) {
        const double n_s = choice.storage == StorageVolume::kPore ? kSquarePorosity : 1.0;
        const double c = k * kBulkModulus / (kViscosity * n_s);
        SceneSpec scene = LatticeScene(side);
        scene.solver.kind = choice.kind;
        scene.solver.storage = choice.storage;
        scene.solver.dt_factor = choice.factor;
        scene.solver.end_time_s = grid.end_T * length * length / c;
        RunOne(scene, side, rows);
      }
    }
    std::fprintf(stderr, "darcy: %d x %d done\n", side, side);
  }
}

}  // namespace seep::bench
