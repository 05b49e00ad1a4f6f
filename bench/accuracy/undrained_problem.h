// Undrained loading (docs/physics.md §5, the V20 test's sample) in the accuracy bench's coupled
// grid: a sealed hex-lattice sample (every wall impermeable) squeezed by four servo walls at the
// same total stress dsigma. The pore fluid takes du/dsigma = (K_f/n)/(K_f/n + K), K the drained
// skeleton's 2D bulk modulus (the same load step without fluid, to rest) and n the storage
// porosity. Error: |du/dsigma measured - du/dsigma at real water| / du/dsigma at real water, the
// measured share being the mean pressure of the sample at rest (4..8 ms). So the error holds both
// what the K_f scaling changed (1/Pi_K - 1/Pi_K(real water) to first order) and what the choices of
// step and interval did.
#pragma once

#include <vector>

#include "accuracy_run.h"
#include "coupled_grid.h"

namespace seep::bench {

CoupledGrid DefaultUndrainedGrid(bool full);

// Appends a row per run (problem "undrained"); progress goes to stderr.
void RunUndrainedGrid(const CoupledGrid& grid, std::vector<AccuracyRun>& rows);

}  // namespace seep::bench
