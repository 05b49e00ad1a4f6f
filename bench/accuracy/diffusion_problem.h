// 1D transient pressure diffusion (docs/physics.md §3.2, case (a) Dirichlet–Dirichlet) on a rigid
// square-lattice strip, run through the real path: SceneSpec -> Simulation.
//
// The strip is `cells` disks long and kStripRows disks wide; the inlet reservoir (p1) and the
// outlet reservoir (0) are the scene's linear boundary, the long sides are no-flow, every free
// domain starts at 0. All domains of a column carry the same pressure, so the strip is a 1D chain
// of cells - 1 free domains between two fixed nodes.
//
// Half-cell rule: a reservoir sits at the image of the end domain's centroid reflected through
// the hull contact, i.e. on the end particles' outer surface, half a cell (R) beyond the centre
// line of the end disks and one cell h = 2R beyond the first domain. So L = cells * h (the
// network's length_m) and the domain k cells from the inlet sits at x/L = k / cells exactly;
// with cells divisible by 4, domains sit at x/L = .25, .5, .75.
//
// Error: max |p/p1 - series| over the domains at x/L = .25/.5/.75 at T = c t / L^2, with
// c = k K_f / (mu n_s), n_s = 1 (apparent volume) or the 2D porosity (pore volume). In T the
// solution is independent of K_f and of the storage choice; they only set the physical time.
#pragma once

#include <vector>

#include "accuracy_run.h"

namespace seep::bench {

struct DiffusionGrid {
  std::vector<double> times;                // T at which the error is measured (one run each)
  std::vector<int> cells;                   // cells along the strip, each divisible by 4
  std::vector<double> bulk_moduli_pa;       // K_f scaling
  std::vector<double> explicit_dt_factors;  // fractions of dt_crit
  std::vector<double> implicit_dt_factors;  // multiples of dt_crit, backward Euler
  // Crank–Nicolson: the implicit ones and longer (second order: far fewer steps for the same error)
  std::vector<double> cn_dt_factors;
  // K_f scaling is run only up to this many cells: in T it changes neither the steps nor the
  // error (the grid shows it), so the finest strips run at real water stiffness only.
  int kf_scaling_max_cells = 160;
  // Runs that would cost more than this many explicit free-domain steps (~3 s) are skipped, except
  // PFC's scheme (explicit, apparent volume, 0.9 dt_crit, real water), which the speed-up
  // needs at every resolution. They lie far off the Pareto front.
  double max_cost = 2e8;
};

DiffusionGrid DefaultDiffusionGrid(bool full);

// Runs the whole grid, appending a row per run; progress goes to stderr.
void RunDiffusionGrid(const DiffusionGrid& grid, std::vector<AccuracyRun>& rows);

// The problem name of the runs at T, e.g. "diffusion_T0.2".
std::string DiffusionProblemName(double T);

}  // namespace seep::bench
