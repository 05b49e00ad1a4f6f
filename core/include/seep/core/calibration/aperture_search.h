// The one-dimensional search behind the calibration (calibration.h), usable with any k(a0): find
// a0 with k(a0) = k_target for a permeability k(a0) that grows with a0, in the variables
// x = log a0, y = log(k / k_target). The Calibrator runs it twice per target: on the affine
// estimate (the first guess) and on the measured permeameter.
//
// Why these steps: when every aperture is proportional to a0, k is proportional to a0^3, so y is
// linear in x with slope 3 and the first step, the cube-root rescale x - y/3, is exact. Open gaps
// (a = a0 + m g) lower the slope below 3 and the cap a_max flattens it, so later steps are secant
// steps through the last two points, which converge superlinearly on this smooth monotone curve.
// Safeguards so that a bad secant cannot diverge: a non-positive or non-finite slope falls back
// to 3; a step changes a0 by at most a factor 1000; once the target is bracketed, a step
// leaving the bracket becomes a bisection; a0 never exceeds a_max.
#pragma once

#include <functional>
#include <limits>

#include "seep/core/status.h"

namespace seep::core {

struct ApertureSearchOptions {
  double tolerance = 1e-6;  // on |k - k_target| / k_target
  int max_evaluations = 30;
  double max_aperture = std::numeric_limits<double>::infinity();
};

struct ApertureSearchPoint {
  double aperture = 0.0;
  double permeability = 0.0;
  double relative_error = 0.0;
};

struct ApertureSearchResult {
  ApertureSearchPoint first;  // at the start value
  ApertureSearchPoint best;   // the smallest relative error met
  int evaluations = 0;
  bool converged = false;
  // The target lies above k(a_max): no a0 allowed by the cap reaches it.
  bool above_cap = false;
};

// k(a0) in m^2; an error stops the search and is returned (e.g. a cancellation).
using PermeabilityAt = std::function<Result<double>(double aperture)>;

Result<ApertureSearchResult> SearchResidualAperture(double target, double start,
                                                    const ApertureSearchOptions& options,
                                                    const PermeabilityAt& permeability_at);

}  // namespace seep::core
