// Darcy steady permeability (docs/physics.md §3.1, V4) on a rigid square lattice of n x n disks,
// Dirichlet inlet/outlet along x, no-flow sides: the measured k = mu Q L / (H dP) (the
// Simulation's permeability_m2, Q the mean of inflow and outflow) against the exact a^3/(24R).
// The steady solver gives it in one solve; the explicit and implicit solvers are run from p = 0
// to T = c t / L^2 = 2 (the slowest mode has decayed by exp(-2 pi^2) ~ 3e-9), which is what
// "running a transient solver to steady state" costs.
#pragma once

#include <vector>

#include "accuracy_run.h"

namespace seep::bench {

struct DarcyGrid {
  std::vector<int> sides;            // disks per side (n x n lattice): steady solver
  std::vector<int> transient_sides;  // the sides also run with the transient solvers
  double end_T = 2.0;
  std::vector<double> implicit_dt_factors;
};

DarcyGrid DefaultDarcyGrid(bool full);

void RunDarcyGrid(const DarcyGrid& grid, std::vector<AccuracyRun>& rows);

}  // namespace seep::bench
