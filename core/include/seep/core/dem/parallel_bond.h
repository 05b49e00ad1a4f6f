// Parallel bonds (PFC2D parallel-bond model, Potyondy & Cundall 2004) between two disks: an
// elastic beam of half-width Rb = radius_multiplier * min(R_i, R_j) acting in parallel with the
// frictional contact. In 2D with unit thickness the bond cross-section has
//   area A = 2 Rb,   second moment I = 2 Rb^3 / 3.
// Forces and moment build up incrementally from the relative motion (so the bond carries no
// force at the moment it is created):
//   dFn = -kn_b A vn dt           (vn > 0 separating; Fn > 0 compression, like the contact law)
//   dFs =  ks_b A vt dt           (force on i along t, same convention as ContactForce::ft)
//   dM  =  kn_b I (omega_j - omega_i) dt   (moment on i; -M on j)
// Maximum stresses on the bond periphery (tension positive):
//   sigma_max = -Fn/A + |M| Rb / I,    tau_max = |Fs| / A
// The bond breaks when sigma_max > tensile_strength or tau_max > shear_strength; from that step
// on it carries nothing and the pair is an ordinary frictional contact while it touches.
#pragma once

#include <cstdint>

#include "seep/core/status.h"

namespace seep::core {

struct BondParams {
  double normal_stiffness = 0.0;   // kn_b, stress / length (> 0)
  double shear_stiffness = 0.0;    // ks_b, stress / length (>= 0)
  double radius_multiplier = 1.0;  // lambda (> 0)
  double tensile_strength = 0.0;   // sigma_c (> 0)
  double shear_strength = 0.0;     // tau_c, the cohesion (> 0)
};

// "dem.bond.tensile_strength: must be finite and > 0 (got 0)".
Status ValidateBondParams(const BondParams& params);

enum class BondFailure : std::uint8_t { kNone = 0, kTension = 1, kShear = 2 };

// The incremental state of one bond.
struct BondState {
  double fn = 0.0;      // normal force, > 0 compression
  double fs = 0.0;      // shear force on i along t
  double moment = 0.0;  // bending moment on i
};

// Bond cross-section of a pair.
inline double BondHalfWidth(const BondParams& p, double ri, double rj) {
  return p.radius_multiplier * (ri < rj ? ri : rj);
}

// Advances a bond by one step and returns how it failed (kNone if it holds). vn, vt and the
// spins follow contact_law.h. On failure the state is left at the values that broke it.
inline BondFailure UpdateBond(const BondParams& p, double half_width, double vn, double vt,
                              double omega_i, double omega_j, double dt, BondState* s) {
  const double area = 2.0 * half_width;
  const double inertia = 2.0 * half_width * half_width * half_width / 3.0;
  s->fn -= p.normal_stiffness * area * vn * dt;
  s->fs += p.shear_stiffness * area * vt * dt;
  s->moment += p.normal_stiffness * inertia * (omega_j - omega_i) * dt;
  const double m_abs = s->moment < 0.0 ? -s->moment : s->moment;
  const double sigma_max = -s->fn / area + m_abs * half_width / inertia;
  const double fs_abs = s->fs < 0.0 ? -s->fs : s->fs;
  if (sigma_max > p.tensile_strength) return BondFailure::kTension;
  if (fs_abs / area > p.shear_strength) return BondFailure::kShear;
  return BondFailure::kNone;
}

// A bond that broke during a step: the pair (i < j) and why.
struct BondBreak {
  std::int32_t i = 0;
  std::int32_t j = 0;
  BondFailure failure = BondFailure::kNone;
};

}  // namespace seep::core
