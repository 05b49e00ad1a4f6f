// Area shared by two overlapping disks (the "lens"), used to count overlap areas once when pore
// volumes are computed from disk sectors.
#pragma once

#include <array>
#include <cstddef>

namespace seep::core {

// F(t) = asin(t) - t sqrt(1 - t^2): the minor circular segment of a unit disk cut by a chord of
// half-length t. DEM overlaps are tiny, so t is small and asin loses to cancellation and speed;
// there the Taylor series F(t) = sum_k 2 c_k t^(2k+3) / (2k+3), c_k = binom(2k, k) / 4^k, is
// used with a fixed number of terms.
inline constexpr int kSegmentSeriesTerms = 14;  // t <= 0.25: the 14th term is below 1e-17

// 2 c_k / (2k + 3), with c_{k+1} = c_k (2k + 1) / (2k + 2), c_0 = 1; built at compile time.
inline constexpr std::array<double, kSegmentSeriesTerms> kSegmentSeries = [] {
  std::array<double, kSegmentSeriesTerms> out{};
  double c = 1.0;
  for (int k = 0; k < kSegmentSeriesTerms; ++k) {
    out[static_cast<std::size_t>(k)] = 2.0 * c / (2.0 * k + 3.0);
    c = c * (2.0 * k + 1.0) / (2.0 * k + 2.0);
  }
  return out;
}();

// F(t) for t < 1/16 (typical DEM overlaps), where 7 terms already reach 1e-17 relative.
// Estrin's scheme: the same polynomial as Horner's to round-off, with a third of its chain of
// dependent operations (the coupled step evaluates it for every overlapping loop contact).
inline double MinorSegmentUnitSmall(double t) {
  const auto& c = kSegmentSeries;
  const double t2 = t * t;
  const double t4 = t2 * t2;
  const double t8 = t4 * t4;
  const double low = (c[0] + c[1] * t2) + (c[2] + c[3] * t2) * t4;
  const double high = (c[4] + c[5] * t2) + c[6] * t4;
  return (low + high * t8) * t2 * t;
}

// Area of the intersection of two disks of radii r1, r2 whose centres are `distance` apart:
// 0 when they do not overlap, pi*min(r1,r2)^2 when one contains the other. Same unit^2 as the
// inputs. The line of centres splits the lens into two halves of equal area.
double LensArea(double r1, double r2, double distance);

}  // namespace seep::core
