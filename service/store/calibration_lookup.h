// The arithmetic of the calibration look-up: how far a stored record is from a probe, and the a0
// interpolated between two records that bracket the target permeability. Pure functions, shared
// by the store's NearestCalibrations and the LookupCalibration RPC.
#pragma once

#include <optional>
#include <vector>

#include "stored_calibration.h"

namespace seep::service {

// Distance in normalized log space:
//   d = sqrt( ln(phi/phi*)^2 + ln(R/R*)^2 + (ln(k/k*)/3)^2 [+ ln(N/N*)^2] [+ ln(z/z*)^2] )
// with phi the porosity, R the mean radius, k the target permeability, N and z the particle count
// and coordination number (only when the probe gives them). Each term is a relative difference
// (ln(1 + x) ~ x), so d = 0.1 means about 10% away, whatever the units. k counts a third because
// a0 scales as k^(1/3): its term is the relative change of a0 that the difference in k implies.
// Non-positive values on either side count as infinitely far.
double CalibrationDistance(const CalibrationProbe& probe, const StoredCalibration& stored);

struct InterpolatedAperture {
  double residual_aperture_m = 0.0;
  StoredCalibration lower;  // the largest stored k <= target
  StoredCalibration upper;  // the smallest stored k >= target
};

// Among the records of ONE setup (same packing, fluid, aperture law and stress), the a0 at
// `permeability_m2` by linear interpolation in (ln k, ln a0) between the two records that
// bracket it; nullopt when none do. Log-log because k = c a0^3 when every aperture is
// proportional to a0, which is a straight line there: the interpolation is then exact. A record
// at exactly the target is returned as both ends.
std::optional<InterpolatedAperture> InterpolateApertureLogLog(
    const std::vector<StoredCalibration>& same_setup, double permeability_m2);

}  // namespace seep::service
