// CalibrationDistance and InterpolateApertureLogLog (calibration_lookup.h).
#include "calibration_lookup.h"

#include <cmath>
#include <limits>

namespace seep::service {
namespace {

// ln(a / b), or infinity when either is not a positive finite number.
double LogRatio(double a, double b) {
  if (!(a > 0.0) || !(b > 0.0) || !std::isfinite(a) || !std::isfinite(b)) {
    return std::numeric_limits<double>::infinity();
  }
  return std::log(a / b);
}

}  // namespace

double CalibrationDistance(const CalibrationProbe& probe, const StoredCalibration& stored) {
  const core::CalibrationRecord& r = stored.record;
  const double porosity = LogRatio(r.packing.porosity_2d, probe.porosity_2d);
  const double radius = LogRatio(r.packing.mean_radius_m, probe.mean_radius_m);
  const double k = LogRatio(r.target_permeability_m2, probe.permeability_m2) / 3.0;
  double sum = porosity * porosity + radius * radius + k * k;
  if (probe.particle_count) {
    const double n = LogRatio(static_cast<double>(r.packing.particle_count), *probe.particle_count);
    sum += n * n;
  }
  if (probe.coordination_number) {
    const double z = LogRatio(r.packing.coordination_number, *probe.coordination_number);
    sum += z * z;
  }
  return std::sqrt(sum);
}

std::optional<InterpolatedAperture> InterpolateApertureLogLog(
    const std::vector<StoredCalibration>& same_setup, double permeability_m2) {
  if (!(permeability_m2 > 0.0) || !std::isfinite(permeability_m2)) return std::nullopt;
  const StoredCalibration* lower = nullptr;
  const StoredCalibration* upper = nullptr;
  for (const StoredCalibration& s : same_setup) {
    const double k = s.record.target_permeability_m2;
    if (!s.record.converged || !(k > 0.0) || !(s.record.residual_aperture_m > 0.0)) continue;
    // Closest on each side; among equal k the newest record (largest row id) wins.
    if (k <= permeability_m2 &&
        (lower == nullptr || k > lower->record.target_permeability_m2 ||
         (k == lower->record.target_permeability_m2 && s.row_id > lower->row_id))) {
      lower = &s;
    }
    if (k >= permeability_m2 &&
        (upper == nullptr || k < upper->record.target_permeability_m2 ||
         (k == upper->record.target_permeability_m2 && s.row_id > upper->row_id))) {
      upper = &s;
    }
  }
  if (lower == nullptr || upper == nullptr) return std::nullopt;
  InterpolatedAperture out{0.0, *lower, *upper};
  const double k_lo = lower->record.target_permeability_m2;
  const double k_hi = upper->record.target_permeability_m2;
  const double a_lo = lower->record.residual_aperture_m;
  const double a_hi = upper->record.residual_aperture_m;
  if (k_lo == k_hi) {
    out.residual_aperture_m = a_lo;
  } else {
    const double t = std::log(permeability_m2 / k_lo) / std::log(k_hi / k_lo);
    out.residual_aperture_m = std::exp(std::log(a_lo) + t * std::log(a_hi / a_lo));
  }
  return out;
}

}  // namespace seep::service
