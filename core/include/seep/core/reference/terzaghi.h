// Terzaghi 1D consolidation with a compressible pore fluid: the analytic reference for the
// coupled oedometer test (docs/physics.md §3.4, verification case V17).
//
// Column of drainage length H, drained at z = 0, impermeable at z = H, load step dsigma at t = 0,
// incompressible grains, fluid bulk modulus K_f, storage porosity n_s, oedometer modulus E_oed:
//   m_v = 1 / E_oed,
//   c_v = k / (mu (m_v + n_s / K_f))                      consolidation coefficient, m^2/s;
//   u0  = dsigma m_v / (m_v + n_s / K_f)                  initial excess pressure (loading
//                                                         efficiency: u0 < dsigma when the
//                                                         fluid is compressible);
//   Tv  = c_v t / H^2;
//   U(Tv)          = 1 - sum_{m>=0} (2/M^2) exp(-M^2 Tv),          M = pi (2m + 1) / 2;
//   u/u0(z/H, Tv)  = sum_{m>=0} (2/M) sin(M z/H) exp(-M^2 Tv);
//   settlement s(t) = (dsigma - u0) m_v H + U(Tv) u0 m_v H  (undrained part + consolidation).
//
// Evaluation: the Fourier series above converges fast for Tv >= 0.1 (exp(-M^2 Tv) < 1e-17 after
// about 6 terms) but slowly for small Tv, where the equivalent image series of erfc terms is used
// instead (fast for small Tv: the n-th term is about erfc(n / sqrt(Tv))). Both are exposed in
// terzaghi_series for the tests that check they agree.
#pragma once

#include "seep/core/status.h"

namespace seep::core {

struct TerzaghiParameters {
  double permeability = 0.0;        // k, m^2
  double viscosity = 1e-3;          // mu, Pa s
  double oedometer_modulus = 0.0;   // E_oed, Pa
  double storage_porosity = 0.0;    // n_s (pore volume the fluid compresses in / total)
  double fluid_bulk_modulus = 0.0;  // K_f, Pa; +infinity = incompressible fluid
  double drainage_length = 0.0;     // H, m
  double load_step = 0.0;           // dsigma, Pa
};

// "coupling.terzaghi.<field>: must be finite and > 0 (got ...)" (n_s >= 0, K_f may be +inf,
// load_step any finite value).
Status ValidateTerzaghiParameters(const TerzaghiParameters& p);

// Unchecked closed forms (validate first).
double ConsolidationCoefficient(const TerzaghiParameters& p);               // c_v, m^2/s
double InitialExcessPressure(const TerzaghiParameters& p);                  // u0, Pa
double TimeFactor(const TerzaghiParameters& p, double time);                // Tv for t in s
double TimeForTimeFactor(const TerzaghiParameters& p, double time_factor);  // t in s
double Settlement(const TerzaghiParameters& p, double time);  // s(t), m (compression > 0)

// U(Tv) in [0, 1]; 0 for Tv <= 0.
double DegreeOfConsolidation(double time_factor);
// u/u0 at depth ratio z/H in [0, 1] (clamped) and Tv; 1 for Tv <= 0 (except 0 at z = 0).
double ExcessPressureRatio(double depth_ratio, double time_factor);

namespace terzaghi_series {
// The two series forms, each summed until its terms stop mattering (relative 1e-17) or 10000
// terms. Fourier: for Tv > 0. Images: for Tv > 0 (used below Tv = 0.1).
double DegreeOfConsolidationFourier(double time_factor);
double DegreeOfConsolidationImages(double time_factor);
double ExcessPressureRatioFourier(double depth_ratio, double time_factor);
double ExcessPressureRatioImages(double depth_ratio, double time_factor);
}  // namespace terzaghi_series

}  // namespace seep::core
