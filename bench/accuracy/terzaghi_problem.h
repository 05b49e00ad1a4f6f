// Terzaghi consolidation (docs/physics.md §3.4) in its rigid-skeleton form, as a flow-only scene
// run through the real path (SceneSpec -> Simulation): a square-lattice strip, `cells` disks along
// x and kColumnRows wide, with a closed inlet (the low end is a no-flow base), the outlet reservoir
// at 0 Pa and every free domain starting at the excess pressure u0. With m_v = 0 (a rigid
// skeleton: the storage is the fluid's compressibility alone) terzaghi.h gives
//   c_v = k K_f / (mu n_s),  Tv = c_v t / H^2,  u/u0(z/H, Tv) and U(Tv),
// with n_s = 1 (apparent volume) or the 2D porosity (pore volume), z measured from the drained
// end. The DEM-coupled column is verified by V17 (tests/core/effects/v17_terzaghi_test.cc); its
// cost is the DEM, not the flow solver, so it says nothing about the solver choice measured here.
//
// Drainage length H: from the closed base to the outlet reservoir's effective position. The base
// is the line of hull contacts at the low end, i.e. the face through which the inlet pipes would
// run (half a cell below the first domain: the no-flow face of a cell-centred scheme); the outlet
// reservoir sits where scene_network.h puts it (the last domain's centroid reflected through the
// hull contacts, on the end particles' outer surface). On the strip H = (2 cells - 1) R =
// (cells - 1/2) h with cells - 1 domains along, h = 2R.
//
// Error: the relative L2 error of the u/u0 profile over all free domains at Tv (default 0.2),
// sqrt(sum (u/u0 - exact)^2 / sum exact^2). The degree of consolidation from the stored fluid,
// U_num = 1 - sum V_s p / sum V_s u0, goes into the note with its error |U_num - U(Tv)|: it is
// not the headline measure because the network stores nothing in the half cell between the last
// domain and the outlet reservoir, so U_num relative to the network's own initial content carries
// an O(h / 2H) offset that no solver choice removes, (1 - U) h / 2H (see docs/accuracy.md). The
// note also gives |dU_H|, U with the initial content referred to the whole column of length H.
#pragma once

#include <string>
#include <vector>

#include "accuracy_run.h"

namespace seep::bench {

struct TerzaghiGrid {
  double time_factor = 0.2;                 // Tv of the error
  std::vector<int> cells;                   // disks along the column
  std::vector<double> explicit_dt_factors;  // fractions of dt_crit (apparent and pore)
  std::vector<double> implicit_dt_factors;  // multiples of dt_crit, backward Euler (pore)
  std::vector<double> cn_dt_factors;        // multiples of dt_crit, Crank–Nicolson (pore)
};

TerzaghiGrid DefaultTerzaghiGrid(bool full);

// Runs the whole grid, appending a row per run (problem "terzaghi"); progress goes to stderr.
void RunTerzaghiGrid(const TerzaghiGrid& grid, std::vector<AccuracyRun>& rows);

}  // namespace seep::bench
