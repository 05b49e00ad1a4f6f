// Terzaghi consolidation of a DEM column between walls (the V17 test's set-up, docs/physics.md
// §3.4) in the accuracy bench's coupled grid: a hex-lattice column, impermeable base and sides, a
// drained servo top platen taking a load step dsigma. The answer a user wants is the column's with
// real water, so every run is compared with the Terzaghi series fed with the column's own E_oed (a
// drained DEM load step), k (its platens' permeameter), n (the storage porosity) and real water's
// K_f, at the physical times where real water is at Tv = 0.05, 0.2 and 0.5 (t counted from the
// load history's centroid, as in V17). Error: the larger of the settlement's error over the final
// settlement and the isochrones' error (8 depth bands, pore-volume weighted) over dsigma. A scaled
// K_f shows up twice: u0 = dsigma Pi_K/(1 + Pi_K) and c_v = k E_oed / (mu (1 + 1/Pi_K)) drop.
#pragma once

#include <vector>

#include "accuracy_run.h"
#include "coupled_grid.h"

namespace seep::bench {

CoupledGrid DefaultConsolidationGrid(bool full);

// Appends a row per run (problem "consolidation"); progress goes to stderr.
void RunConsolidationGrid(const CoupledGrid& grid, std::vector<AccuracyRun>& rows);

}  // namespace seep::bench
