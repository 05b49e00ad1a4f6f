#include "seep/core/geometry/disk_overlap.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace seep::core {
namespace {

double MinorSegmentUnit(double t) {
  if (t > 0.25) return std::asin(t) - t * std::sqrt(std::max(0.0, 1.0 - t * t));
  if (t < 0.0625) return MinorSegmentUnitSmall(t);
  const double t2 = t * t;
  double sum = 0.0;
  for (int k = kSegmentSeriesTerms - 1; k >= 0; --k) {
    sum = sum * t2 + kSegmentSeries[static_cast<std::size_t>(k)];
  }
  return sum * t2 * t;
}

// Area of the part of a disk of radius r beyond a chord of half-length h whose distance from the
// centre is a (a < 0: the centre is on the cut-off side, so the segment is the major one).
double Segment(double r, double h, double a) {
  const double minor = r * r * MinorSegmentUnit(std::min(1.0, h / r));
  return a >= 0.0 ? minor : std::numbers::pi * r * r - minor;
}

}  // namespace

double LensArea(double r1, double r2, double distance) {
  if (!(distance < r1 + r2)) return 0.0;
  const double r_small = std::min(r1, r2);
  if (distance <= std::abs(r1 - r2)) return std::numbers::pi * r_small * r_small;
  const double d = distance;
  double shallow = 0.0;
  if (ShallowLensArea(r1, r2, 1.0 / r1, 1.0 / r2, d, &shallow)) return shallow;
  // Deeper overlaps: the same formulas with the exact segments.
  const double a1 = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
  const double a2 = d - a1;
  const double h =
      std::sqrt(std::max(0.0, (r1 + r2 + d) * (r1 + r2 - d) * (d + r1 - r2) * (d - r1 + r2))) /
      (2.0 * d);
  return Segment(r1, h, a1) + Segment(r2, h, a2);
}

}  // namespace seep::core
