// Safeguarded secant search for the residual aperture (aperture_search.h).
#include "seep/core/calibration/aperture_search.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace seep::core {
namespace {

// d log k / d log a0 when every aperture is proportional to a0 (cubic law).
constexpr double kProportionalSlope = 3.0;
// Largest change of a0 in one step: a flat curve (capped or gap-dominated pipes) must not throw
// a0 to 0 or infinity.
const double kMaxLogStep = std::log(1000.0);

struct Sample {
  double x = 0.0;  // log a0
  double y = 0.0;  // log(k / k_target)
  ApertureSearchPoint point;
};

}  // namespace

Result<ApertureSearchResult> SearchResidualAperture(double target, double start,
                                                    const ApertureSearchOptions& options,
                                                    const PermeabilityAt& permeability_at) {
  const double x_max = std::log(options.max_aperture);  // +inf without a cap
  if (!std::isfinite(target) || target <= 0.0 || !std::isfinite(start) || start <= 0.0 ||
      !(options.max_aperture > 0.0) || options.max_evaluations < 1 || !(options.tolerance > 0.0)) {
    return InvalidArgument(fmt::format(
        "calibration search: needs target > 0 (got {}), start > 0 (got {}), max_aperture > 0 (got "
        "{}), max_evaluations >= 1 (got {}) and tolerance > 0 (got {})",
        target, start, options.max_aperture, options.max_evaluations, options.tolerance));
  }
  ApertureSearchResult result;
  auto evaluate = [&](double aperture) -> Result<Sample> {
    SEEP_ASSIGN_OR_RETURN(const double k, permeability_at(aperture));
    if (!std::isfinite(k) || k <= 0.0) {
      return FailedPrecondition(fmt::format(
          "calibration: the permeameter measures k = {} m^2 at a0 = {} m; it needs k > 0", k,
          aperture));
    }
    ++result.evaluations;
    return Sample{
        std::log(aperture), std::log(k / target), {aperture, k, std::abs(k - target) / target}};
  };

  SEEP_ASSIGN_OR_RETURN(Sample current, evaluate(std::min(start, options.max_aperture)));
  result.first = current.point;
  result.best = current.point;
  Sample previous;
  bool have_previous = false;
  double below = -std::numeric_limits<double>::infinity();  // largest x with k < target
  double above = std::numeric_limits<double>::infinity();   // smallest x with k > target
  while (true) {
    if (current.point.relative_error < result.best.relative_error) result.best = current.point;
    if (current.point.relative_error < options.tolerance) {
      result.converged = true;
      break;
    }
    if (current.y < 0.0) below = std::max(below, current.x);
    if (current.y > 0.0) above = std::min(above, current.x);
    if (current.y < 0.0 && current.point.aperture >= options.max_aperture) {
      result.above_cap = true;
      break;
    }
    if (result.evaluations >= options.max_evaluations) break;

    double slope = kProportionalSlope;
    if (have_previous && current.x != previous.x) {
      const double secant = (current.y - previous.y) / (current.x - previous.x);
      if (std::isfinite(secant) && secant > 0.0) slope = secant;
    }
    double x = current.x - current.y / slope;
    x = std::clamp(x, current.x - kMaxLogStep, current.x + kMaxLogStep);
    x = std::min(x, x_max);
    if (std::isfinite(below) && std::isfinite(above) && !(x > below && x < above)) {
      x = 0.5 * (below + above);
    }
    if (x == current.x) break;  // no representable progress left
    // The first step keeps the exact cube-root form a0 (k_target/k)^(1/3) (no exp/log round
    // trip) so that the proportional case lands on the target to the solver's precision; the cap
    // is used as given.
    double aperture = std::exp(x);
    if (x >= x_max) {
      aperture = options.max_aperture;
    } else if (!have_previous && x == current.x - current.y / kProportionalSlope) {
      aperture = current.point.aperture * std::cbrt(target / current.point.permeability);
    }
    previous = current;
    have_previous = true;
    SEEP_ASSIGN_OR_RETURN(current, evaluate(aperture));
  }
  return result;
}

}  // namespace seep::core
