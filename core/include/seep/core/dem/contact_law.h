// The linear spring-dashpot contact law with Coulomb friction (LAMMPS gran/hooke/history, PFC
// linear model), as a pure function of explicit inputs so that it can be unit-tested and run in
// parallel. The same law serves disk-disk and disk-wall contacts (a wall is a body of infinite
// mass: the reduced mass is then the disk's mass).
//
// Geometry and signs (2D): n is the unit normal from body i to body j, t = (-n_y, n_x) (z x n).
//   overlap  delta = -gap (> 0 when the bodies interpenetrate)
//   vn       relative normal velocity of j with respect to i at the contact, > 0 when separating
//   vt       relative tangential velocity of j w.r.t. i at the contact point, along t
//            (includes the spins: vt = (v_j - v_i).t - omega_i R_i - omega_j R_j)
// Outputs:
//   fn       normal force, > 0 in compression: fn = kn delta - c vn, with c = m_eff gamma_n
//            (or c = 2 zeta sqrt(kn m_eff) when the damping is given as a critical ratio zeta).
//            Not clamped at zero (as LAMMPS gran/hooke), so that the analytic spring-dashpot
//            solution holds; friction uses max(fn, 0).
//   ft       tangential force on i along t (the force on j is -ft t). It is also the shear
//            history: ft <- ft + kt vt dt, then |ft| <= mu max(fn, 0) (slip caps the history).
// The force on i is -fn n + ft t; the torques are R_i ft on i and R_j ft on j.
#pragma once

#include <algorithm>
#include <cmath>

#include "seep/core/status.h"

namespace seep::core {

enum class NormalDampingMode {
  kPerReducedMass,  // c = m_eff * gamma_n  (the shared benchmark's gamma_n, LAMMPS convention)
  kCriticalRatio,   // c = 2 * zeta * sqrt(kn * m_eff), zeta = damping_ratio (1 = critical)
};

struct ContactLawParams {
  double kn = 0.0;        // normal stiffness, force / length (per unit thickness), > 0
  double kt = 0.0;        // tangential stiffness, >= 0
  double friction = 0.0;  // Coulomb coefficient mu, >= 0
  NormalDampingMode damping_mode = NormalDampingMode::kPerReducedMass;
  double gamma_n = 0.0;        // 1/time, used with kPerReducedMass, >= 0
  double damping_ratio = 0.0;  // used with kCriticalRatio, >= 0
};

// Names the field: "dem.contact.kn: must be finite and > 0 (got -1)".
Status ValidateContactLawParams(const ContactLawParams& params);

// The viscous coefficient c of the law for a pair of reduced mass m_eff.
inline double NormalDampingCoefficient(const ContactLawParams& p, double m_eff) {
  return p.damping_mode == NormalDampingMode::kPerReducedMass
             ? m_eff * p.gamma_n
             : 2.0 * p.damping_ratio * std::sqrt(p.kn * m_eff);
}

struct ContactForce {
  double fn;  // normal force, > 0 compressive
  double ft;  // tangential force on i along t (= the new shear history)
};

// One evaluation of the law for a contact with overlap > 0 (callers skip open contacts and reset
// their history). `damping` is NormalDampingCoefficient(params, m_eff), passed in so that the hot
// loop can precompute it per pair. shear_history is the previous ft.
inline ContactForce EvaluateLinearContact(double overlap, double vn, double vt, double damping,
                                          double kn, double kt, double friction,
                                          double shear_history, double dt) {
  const double fn = kn * overlap - damping * vn;
  double ft = shear_history + kt * vt * dt;
  const double cap = friction * std::max(fn, 0.0);
  ft = std::clamp(ft, -cap, cap);
  return {fn, ft};
}

// Convenience overload taking the parameter struct (tests, slow paths).
inline ContactForce EvaluateLinearContact(const ContactLawParams& p, double overlap, double vn,
                                          double vt, double m_eff, double shear_history,
                                          double dt) {
  return EvaluateLinearContact(overlap, vn, vt, NormalDampingCoefficient(p, m_eff), p.kn, p.kt,
                               p.friction, shear_history, dt);
}

// Analytic results of the linear spring-dashpot (kPerReducedMass), used by the tests and
// documentation: duration of a collision t_c = pi / sqrt(kn/m_eff - (gamma_n/2)^2) and normal
// restitution e = exp(-gamma_n t_c / 2). Valid when gamma_n < 2 sqrt(kn/m_eff) (underdamped).
double SpringDashpotContactDuration(double kn, double m_eff, double gamma_n);
double SpringDashpotRestitution(double kn, double m_eff, double gamma_n);

}  // namespace seep::core
