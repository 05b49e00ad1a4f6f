// Area shared by two overlapping disks (the "lens"), used to count overlap areas once when pore
// volumes are computed from disk sectors.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
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

// Half the lens of two disks of radii r1, r2 at surface gap `gap` (negative = overlap): the part
// on either side of the line of centres, which domain detection gives to each face beside the
// contact. 0 without overlap (and for a NaN gap).
inline double HalfPairLens(double r1, double r2, double gap) {
  return gap < 0.0 ? 0.5 * LensArea(r1, r2, r1 + r2 + gap) : 0.0;
}

// The lens of two disks of radii r1, r2 (inv_r1 = 1/r1, inv_r2 = 1/r2) whose centres are d apart,
// by LensArea's formulas, without a branch, for what a DEM contact loop meets: a shallow overlap
// (chord half-length below R/16 on both disks, both segments minor) or no overlap at all (the
// Heron product clamps to 0, so h = 0 and so is the area). Sets *area and returns whether the
// pair is one of those; otherwise *area is meaningless and LensArea gives the answer.
inline bool ShallowLensArea(double r1, double r2, double inv_r1, double inv_r2, double d,
                            double* area) {
  const double sum = r1 + r2;
  const double diff = r1 - r2;
  const double inv_2d = 0.5 / d;
  // Distances from each centre to the common chord, and the chord's half-length (Heron form,
  // accurate when the overlap r1 + r2 - d is tiny).
  const double a1 = (d * d + r1 * r1 - r2 * r2) * inv_2d;
  const double a2 = d - a1;
  const double h =
      std::sqrt(std::max(0.0, (sum + d) * (sum - d) * (d + diff) * (d - diff))) * inv_2d;
  const double t1 = h * inv_r1;
  const double t2 = h * inv_r2;
  *area = r1 * r1 * MinorSegmentUnitSmall(t1) + r2 * r2 * MinorSegmentUnitSmall(t2);
  return (d > std::abs(diff)) & (a1 >= 0.0) & (a2 >= 0.0) & (t1 < 0.0625) & (t2 < 0.0625);
}

}  // namespace seep::core
