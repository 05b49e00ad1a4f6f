// Hydraulic aperture of a contact pipe from its mechanical state (docs/physics.md §2.3, seed eqs.
// 2-3), and the cubic-law conductance (seed eq. 1).
//
//   F > 0 (compressive normal force, N per m):  a = a0 F0 / (F + F0)        (eq. 2)
//   F <= 0 (zero or tensile), gap g >= 0 (m):    a = a0 + m g                 (eq. 3)
//   optional clamp a <= a_max (a physics change: document it when used, docs/physics.md §4.4 item
//   6).
// Both branches give a0 at F = g = 0, so the law is continuous there. In the compressive branch
// the gap is ignored (a compressed contact has no gap).
#pragma once

#include <limits>
#include <span>

#include "seep/core/status.h"

namespace seep::core {

struct ApertureLaw {
  double residual_aperture = 0.0;  // a0, m (> 0); calibrate from k, docs/physics.md §1.3.
  double reference_force = 1.0;    // F0, N per m (> 0): the force that halves the aperture.
  double gap_multiplier = 0.0;     // m, dimensionless (>= 0).
  double max_aperture = std::numeric_limits<double>::infinity();  // a_max, m (>= a0).
};

// "flow.aperture_law.<field>: ..." on bad parameters.
Status ValidateApertureLaw(const ApertureLaw& law);

// Pure function; the law must be valid. A negative gap (overlap) with F <= 0 counts as g = 0.
// Both branches are evaluated and one selected, so that a loop over pipes vectorises.
inline double Aperture(const ApertureLaw& law, double normal_force, double gap) {
  const double compressive = normal_force > 0.0 ? normal_force : 0.0;
  const double by_force =
      law.residual_aperture * law.reference_force / (compressive + law.reference_force);
  const double by_gap = law.residual_aperture + law.gap_multiplier * (gap > 0.0 ? gap : 0.0);
  const double a = normal_force > 0.0 ? by_force : by_gap;
  return a < law.max_aperture ? a : law.max_aperture;
}

// Cubic law C = a^3/(12 mu L), m^2/(Pa s), so that q = C dP.
inline double PipeConductance(double aperture, double viscosity, double length) {
  return aperture * aperture * aperture / (12.0 * viscosity * length);
}

// Fills aperture[p] and conductance[p] for every pipe from normal_force[p], gap[p], length[p].
// All spans must have the same size; lengths must be > 0 and the viscosity > 0.
Status FillAperturesAndConductances(const ApertureLaw& law, double viscosity,
                                    std::span<const double> normal_force,
                                    std::span<const double> gap, std::span<const double> length,
                                    std::span<double> aperture, std::span<double> conductance);

}  // namespace seep::core
