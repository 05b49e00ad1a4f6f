#include "seep/core/geometry/disk_overlap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace seep::core {
namespace {

// F(t) = asin(t) - t sqrt(1 - t^2): the minor circular segment of a unit disk cut by a chord of
// half-length t. DEM overlaps are tiny, so t is small and asin loses to cancellation and speed;
// there the Taylor series F(t) = sum_k 2 c_k t^(2k+3) / (2k+3), c_k = binom(2k, k) / 4^k, is
// used with a fixed number of terms (t <= 0.25: the 14th term is below 1e-17 relative).
constexpr int kSeriesTerms = 14;

// 2 c_k / (2k + 3), with c_{k+1} = c_k (2k + 1) / (2k + 2), c_0 = 1; built at compile time.
constexpr auto kSeries = [] {
  std::array<double, kSeriesTerms> out{};
  double c = 1.0;
  for (int k = 0; k < kSeriesTerms; ++k) {
    out[static_cast<std::size_t>(k)] = 2.0 * c / (2.0 * k + 3.0);
    c = c * (2.0 * k + 1.0) / (2.0 * k + 2.0);
  }
  return out;
}();

double MinorSegmentUnit(double t) {
  if (t > 0.25) return std::asin(t) - t * std::sqrt(std::max(0.0, 1.0 - t * t));
  const double t2 = t * t;
  // Typical DEM overlaps give t < 1/16, where 7 terms already reach 1e-17 relative.
  const int terms = t < 0.0625 ? 7 : kSeriesTerms;
  double sum = 0.0;
  for (int k = terms - 1; k >= 0; --k) sum = sum * t2 + kSeries[static_cast<std::size_t>(k)];
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
  // Distances from each centre to the common chord, and the chord's half-length (Heron form,
  // accurate when the overlap r1 + r2 - d is tiny).
  const double a1 = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
  const double a2 = d - a1;
  const double h =
      std::sqrt(std::max(0.0, (r1 + r2 + d) * (r1 + r2 - d) * (d + r1 - r2) * (d - r1 + r2))) /
      (2.0 * d);
  return Segment(r1, h, a1) + Segment(r2, h, a2);
}

}  // namespace seep::core
