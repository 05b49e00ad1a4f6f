// Radial injection, steady (docs/physics.md §3.3, V12): a hex lattice cut to an annulus, the
// central hole held at p_w, the outer hull pipes to a reservoir at p_e = 0, against Thiem with the
// effective well radius r_w,eff fitted from the profile (the discrete hole is not its nominal
// radius) and r_e the network's outer reservoir radius, as in tests/core/scene/
// verification_thiem_test.cc. Error: the largest deviation of ring means (rings 2R wide) from
// the Thiem profile over 3R + r_w < r < 0.8 r_e, as a fraction of p_w - p_e; the rate error
// |Q - Q_Thiem| / Q_Thiem goes into the note.
#pragma once

#include <vector>

#include "accuracy_run.h"

namespace seep::bench {

struct ThiemGrid {
  std::vector<int> outer_radii_in_r;      // r_e / R, well radius 5 R; resolution = r_e / (2R)
  std::vector<int> transient_radii_in_r;  // also run with backward Euler to steady state
  std::vector<double> implicit_dt_factors;
  double end_T = 2.0;  // t c / r_e^2 for the transient runs
};

ThiemGrid DefaultThiemGrid(bool full);

void RunThiemGrid(const ThiemGrid& grid, std::vector<AccuracyRun>& rows);

}  // namespace seep::bench
