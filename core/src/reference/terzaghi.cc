// Terzaghi consolidation: closed forms and the two series (see terzaghi.h).
//
// Image series (from the method of images for the drained/impermeable column, z measured from
// the drained face, zeta = z/H, tau = Tv):
//   u/u0 = 1 - sum_{n>=0} (-1)^n [erfc((2n + zeta) / (2 sqrt tau)) + erfc((2n + 2 - zeta) / (2 sqrt
//   tau))] U    = 2 sqrt(tau) [1/sqrt(pi) + 2 sum_{n>=1} (-1)^n ierfc(n / sqrt tau)],
//          ierfc(x) = exp(-x^2)/sqrt(pi) - x erfc(x),
// the second being the depth average of 1 - u/u0 (the integral of erfc is ierfc).
#include "seep/core/reference/terzaghi.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace seep::core {
namespace {

constexpr int kMaxTerms = 10000;
constexpr double kTermTolerance = 1e-17;
// Below this Tv the image series is used (about 3 terms there); above it the Fourier series
// (about 6 terms at Tv = 0.1, fewer later).
constexpr double kSeriesSwitch = 0.1;

double Ierfc(double x) { return std::exp(-x * x) / std::sqrt(std::numbers::pi) - x * std::erfc(x); }

std::string Got(double v) { return " (got " + std::to_string(v) + ")"; }

Status CheckPositive(double v, const char* field) {
  if (!(std::isfinite(v) && v > 0.0)) {
    return InvalidArgument(std::string("coupling.terzaghi.") + field + ": must be finite and > 0" +
                           Got(v));
  }
  return Status::Ok();
}

double StorageCompressibility(const TerzaghiParameters& p) {
  // n_s / K_f, 0 for an incompressible fluid (K_f = +inf).
  return p.storage_porosity / p.fluid_bulk_modulus;
}

}  // namespace

Status ValidateTerzaghiParameters(const TerzaghiParameters& p) {
  SEEP_RETURN_IF_ERROR(CheckPositive(p.permeability, "permeability"));
  SEEP_RETURN_IF_ERROR(CheckPositive(p.viscosity, "viscosity"));
  SEEP_RETURN_IF_ERROR(CheckPositive(p.oedometer_modulus, "oedometer_modulus"));
  SEEP_RETURN_IF_ERROR(CheckPositive(p.drainage_length, "drainage_length"));
  if (!(std::isfinite(p.storage_porosity) && p.storage_porosity >= 0.0)) {
    return InvalidArgument("coupling.terzaghi.storage_porosity: must be finite and >= 0" +
                           Got(p.storage_porosity));
  }
  if (!(p.fluid_bulk_modulus > 0.0)) {  // +inf allowed; NaN fails here
    return InvalidArgument("coupling.terzaghi.fluid_bulk_modulus: must be > 0 (or +inf)" +
                           Got(p.fluid_bulk_modulus));
  }
  if (!std::isfinite(p.load_step)) {
    return InvalidArgument("coupling.terzaghi.load_step: must be finite" + Got(p.load_step));
  }
  return Status::Ok();
}

double ConsolidationCoefficient(const TerzaghiParameters& p) {
  const double mv = 1.0 / p.oedometer_modulus;
  return p.permeability / (p.viscosity * (mv + StorageCompressibility(p)));
}

double InitialExcessPressure(const TerzaghiParameters& p) {
  const double mv = 1.0 / p.oedometer_modulus;
  return p.load_step * mv / (mv + StorageCompressibility(p));
}

double TimeFactor(const TerzaghiParameters& p, double time) {
  return ConsolidationCoefficient(p) * time / (p.drainage_length * p.drainage_length);
}

double TimeForTimeFactor(const TerzaghiParameters& p, double time_factor) {
  return time_factor * p.drainage_length * p.drainage_length / ConsolidationCoefficient(p);
}

double Settlement(const TerzaghiParameters& p, double time) {
  const double mv = 1.0 / p.oedometer_modulus;
  const double u0 = InitialExcessPressure(p);
  const double undrained = (p.load_step - u0) * mv * p.drainage_length;
  return undrained + DegreeOfConsolidation(TimeFactor(p, time)) * u0 * mv * p.drainage_length;
}

double DegreeOfConsolidation(double time_factor) {
  if (!(time_factor > 0.0)) return 0.0;
  return time_factor < kSeriesSwitch ? terzaghi_series::DegreeOfConsolidationImages(time_factor)
                                     : terzaghi_series::DegreeOfConsolidationFourier(time_factor);
}

double ExcessPressureRatio(double depth_ratio, double time_factor) {
  const double zeta = std::clamp(depth_ratio, 0.0, 1.0);
  if (zeta == 0.0) return 0.0;  // the drained face
  if (!(time_factor > 0.0)) return 1.0;
  return time_factor < kSeriesSwitch
             ? terzaghi_series::ExcessPressureRatioImages(zeta, time_factor)
             : terzaghi_series::ExcessPressureRatioFourier(zeta, time_factor);
}

namespace terzaghi_series {

double DegreeOfConsolidationFourier(double time_factor) {
  double sum = 0.0;
  for (int m = 0; m < kMaxTerms; ++m) {
    const double big_m = std::numbers::pi * (2.0 * m + 1.0) / 2.0;
    const double term = 2.0 / (big_m * big_m) * std::exp(-big_m * big_m * time_factor);
    sum += term;
    if (term < kTermTolerance) break;
  }
  return 1.0 - sum;
}

double DegreeOfConsolidationImages(double time_factor) {
  const double root = std::sqrt(time_factor);
  double sum = 1.0 / std::sqrt(std::numbers::pi);
  double sign = -1.0;
  for (int n = 1; n < kMaxTerms; ++n) {
    const double term = 2.0 * Ierfc(n / root);
    sum += sign * term;
    sign = -sign;
    if (term < kTermTolerance) break;
  }
  return 2.0 * root * sum;
}

double ExcessPressureRatioFourier(double depth_ratio, double time_factor) {
  double sum = 0.0;
  for (int m = 0; m < kMaxTerms; ++m) {
    const double big_m = std::numbers::pi * (2.0 * m + 1.0) / 2.0;
    const double decay = std::exp(-big_m * big_m * time_factor);
    sum += 2.0 / big_m * std::sin(big_m * depth_ratio) * decay;
    if (2.0 / big_m * decay < kTermTolerance) break;
  }
  return sum;
}

double ExcessPressureRatioImages(double depth_ratio, double time_factor) {
  const double scale = 1.0 / (2.0 * std::sqrt(time_factor));
  double sum = 0.0;
  double sign = 1.0;
  for (int n = 0; n < kMaxTerms; ++n) {
    const double term = std::erfc((2.0 * n + depth_ratio) * scale) +
                        std::erfc((2.0 * n + 2.0 - depth_ratio) * scale);
    sum += sign * term;
    sign = -sign;
    if (term < kTermTolerance) break;
  }
  return 1.0 - sum;
}

}  // namespace terzaghi_series
}  // namespace seep::core
