// The affine (uniform-gradient) permeability estimate of a pipe network, docs/physics.md §1.3 (C1).
//
// A linear pressure field P = -G x along the unit axis e makes every pipe p carry
// q_p = C_p (d_p . e) G, with d_p the vector between the centroids of the two domains it joins.
// Summed over the sample area A (the area the domains tile, sum V_d):
//
//   k_e = (mu / A) sum_p C_p (d_p . e)^2 = a^3 / (12 A) sum_p (d_p . e)^2 / L_p   (uniform a),
//
// which for an isotropic network (sum (d.e)^2 = 1/2 sum |d|^2) is the paper-style
// k = a^3/(24 A) sum |d|^2 / L. It is exact on lattices and an upper bound on disordered networks
// (the Dirichlet principle), so a calibration uses it as a first guess and then corrects
// a0 <- a0 (k_target / k_measured)^(1/3), which is exact when every aperture is proportional to a0.
#pragma once

#include "seep/core/geometry/domain_detection.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {

// k_e / a^3 in m^2 per m^3 (1/m): the permeability along `axis` per cubed uniform aperture.
// Only pipes between two domains count (boundary pipes have no second centroid). Returns 0 for a
// network with no domains.
double AffinePermeabilityPerCubedAperture(const DomainNetwork& domains, FlowAxis axis);

}  // namespace seep::core
