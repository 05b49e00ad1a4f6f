// Buoyancy: the part of the pore-fluid force that the fluid's weight adds
// (docs/guide/fluid-weight.md).
//
// With weight w = rho_f g (Pa/m) the fluid of each face is at rest within the face, so the
// pressure on its arcs is linear: p(x) = Phi_F + w.x, Phi_F = P_F - w.x_F the face's head. The
// force on a particle splits exactly into
//   - the chord rule (pressure_forces.h) applied to the heads Phi_F: constant per face, so the
//     rule is exact for this part, and a fluid at rest (one head everywhere) cancels to the bit;
//   - the force of the field w.x on the whole wetted circle: -w pi R^2 (Archimedes), whatever
//     faces the arcs belong to, since the arcs between a particle's contact points cover its
//     circle.
// The second part is added here, to every particle: each arc of a disk is wetted by a domain, an
// island's host, or the boundary fluid of the outer walk (pressure_forces.h). A fluid at rest
// thus pushes the assembly up by exactly rho_f g x the solid area. Disks that overlap (DEM
// contacts) count their lens twice, an error of the order of overlap/R.
#pragma once

#include <span>

#include "seep/core/coupling/particle_view.h"

namespace seep::core {

// fx[i] -= wx pi r_i^2, fy[i] -= wy pi r_i^2 (sizes: the caller's duty; the hot path). One pass
// per particle, written per item: the same bits on any thread count.
void AddBuoyancy(const ParticleView& particles, double wx, double wy, double* fx, double* fy);

}  // namespace seep::core
