// Hydraulic-fracturing breakdown (the hydrofrac test's scene, docs/physics.md §5) in the accuracy
// bench's coupled grid: a bonded hex lattice confined by four drained servo walls at sigma, water
// injected at a constant rate into a well in its centre, run until the first bond breaks. The
// compared number is the initiation pressure, the well pressure at which the first bond broke:
// the peak that follows it on the lattice is set by the unstable burst of bond breaks (it spikes
// by tens of per cent from one flow update to the next), not by the pressurisation, so it cannot
// tell a choice's error from the burst's noise. No closed form holds for the lattice to better than
// its bond geometry (Hubbert-Willis 2 sigma + T), so each run is compared with the same scene at
// real water: error |P_i - P_i(real water)| / P_i(real water). At a fixed injection rate the well
// pressurises more slowly as K_f falls (the fluid's storage V/K_f grows), so the end time is a cap
// scaled with 1/K_f and 1/rate; every run stops at its first break. Each row's note also gives the
// time to the first break over the sample's wave-crossing time t_w = L / sqrt(K / rho_b) (K the
// run's coupling_skeleton_bulk_modulus_pa): the number that says whether the injection was slow
// enough for the skeleton to follow it.
#pragma once

#include <string>
#include <vector>

#include "accuracy_run.h"
#include "coupled_grid.h"

namespace seep::bench {

struct BreakdownGrid {
  std::string problem;               // the rows' problem name
  double injection_rate_m2_s = 0.0;  // into the well
  CoupledGrid grid;
};

// Two injection rates: "breakdown" at 2e-5 m^2/s, where real water's well reaches its first break
// in ~1.4 ms (a few of the lattice's wave-crossing times, so its answer is still rate dependent),
// and "breakdown-slow" at 2.5e-6, where real water takes ~10 ms and the scaled fluids longer.
std::vector<BreakdownGrid> DefaultBreakdownGrids(bool full);

// Appends a row per run (problem grid.problem); progress goes to stderr.
void RunBreakdownGrid(const BreakdownGrid& grid, std::vector<AccuracyRun>& rows);

// Real water alone (the grids' base choice) at injection rates from 2e-5 down to 1.25e-6 m^2/s:
// how the initiation pressure itself depends on the rate, which decides whether comparing a
// scaled fluid with real water at one rate says anything. Rows "breakdown-rate", error against
// the slowest rate.
void RunBreakdownRates(std::vector<AccuracyRun>& rows);

}  // namespace seep::bench
