// Lens area of two disks against the closed form from two circular segments.
#include "seep/core/geometry/disk_overlap.h"

#include <gtest/gtest.h>

#include <cmath>

#include "geometry_test_util.h"

namespace seep::core {
namespace {

using testing::kPi;

// Reference by quadrature, free of cancellation for tiny overlaps: the lens is the integral over
// the chord coordinate y of its width w(y) = delta - y^2/(s1 + r1) - y^2/(s2 + r2),
// s = sqrt(r^2 - y^2), delta = r1 + r2 - d; substituting y = h sin(phi) makes the integrand
// smooth, and composite Simpson with 4000 panels is exact to rounding here.
double IntegratedLens(double r1, double r2, double delta) {
  const double d = r1 + r2 - delta;
  const double h2 = delta * (r1 + r2 + d) * (d + r1 - r2) * (d - r1 + r2) / (4 * d * d);
  const double h = std::sqrt(h2);
  auto integrand = [&](double phi) {
    const double y = h * std::sin(phi);
    const double w = delta - y * y / (std::sqrt(r1 * r1 - y * y) + r1) -
                     y * y / (std::sqrt(r2 * r2 - y * y) + r2);
    return w * h * std::cos(phi);
  };
  const int panels = 4000;
  const double step = kPi / panels;
  double sum = integrand(-kPi / 2) + integrand(kPi / 2);
  for (int k = 1; k < panels; ++k) sum += (k % 2 ? 4 : 2) * integrand(-kPi / 2 + k * step);
  return sum * step / 3;
}

TEST(DiskOverlap, LensMatchesQuadratureForSmallOverlaps) {
  // DEM-sized overlaps, 1e-9 .. 0.3 of the smaller radius (both branches of the library's
  // segment evaluation; the centres stay outside the other disk so w(y) >= 0 holds).
  for (const double r2 : {1.0, 0.4, 2.5}) {
    for (const double ratio : {1e-9, 1e-6, 1e-3, 0.02, 0.1, 0.3}) {
      const double r1 = 1.0;
      const double d = r1 + r2 - ratio * std::min(r1, r2);
      // The overlap the library sees is that of the rounded distance (exact subtraction).
      const double delta = (r1 + r2) - d;
      const double want = IntegratedLens(r1, r2, delta);
      const double got = LensArea(r1, r2, d);
      EXPECT_NEAR(got, want, 1e-12 * want) << "r2 " << r2 << " overlap " << ratio;
      EXPECT_NEAR(LensArea(r2, r1, d), got, 1e-14 * got);
    }
  }
}

TEST(DiskOverlap, LensMatchesSegmentFormulaForDeepOverlaps) {
  // Deep overlaps, including a centre beyond the common chord (major segment).
  for (const double r2 : {1.0, 0.4, 2.5}) {
    for (const double ratio : {0.3, 0.6, 0.9, 1.3}) {
      const double r1 = 1.0;
      const double d = r1 + r2 - ratio * std::min(r1, r2);
      if (d <= std::abs(r1 - r2)) continue;
      const double want = testing::SegmentLens(r1, r2, d);
      EXPECT_NEAR(LensArea(r1, r2, d), want, 1e-13 * want) << "r2 " << r2 << " overlap " << ratio;
    }
  }
}

TEST(DiskOverlap, LimitCases) {
  EXPECT_EQ(LensArea(1.0, 1.0, 2.0), 0.0);
  EXPECT_EQ(LensArea(1.0, 1.0, 3.0), 0.0);
  EXPECT_DOUBLE_EQ(LensArea(1.0, 0.5, 0.2), kPi * 0.25);  // small disk inside the big one
  // Equal disks at distance R: lens = 2 (pi/3 - sqrt3/4) R^2 (two 120-degree segments).
  EXPECT_NEAR(LensArea(1.0, 1.0, 1.0), 2 * (kPi / 3 - std::sqrt(3.0) / 4), 1e-15);
}

}  // namespace
}  // namespace seep::core
