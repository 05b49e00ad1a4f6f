// The safeguarded cube-root/secant search (aperture_search.h) on closed-form k(a0) curves: exact
// in one step when k is proportional to a0^3, superlinear with open gaps, and bounded (no
// divergence, no NaN) when no a0 can reach the target.
#include "seep/core/calibration/aperture_search.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace seep::core {
namespace {

constexpr double kTarget = 1e-13;
constexpr double kPerCubedAperture = 1.0 / 24e-3;  // square lattice, R = 1 mm: k = a^3/(24 R)

Result<ApertureSearchResult> Search(double start, const ApertureSearchOptions& options,
                                    double (*k)(double)) {
  return SearchResidualAperture(kTarget, start, options,
                                [k](double a0) -> Result<double> { return k(a0); });
}

double Cubic(double a0) { return kPerCubedAperture * a0 * a0 * a0; }
// Every pipe open by 5 um with m = 1: a = a0 + 5e-6 is not proportional to a0.
double OpenGap(double a0) { return Cubic(a0 + 5e-6); }
// Monotone but with a slope d log k / d log a0 = 3 + 0.9 cos(3 log a0) swinging in [2.1, 3.9].
double Wiggly(double a0) { return Cubic(a0) * std::exp(0.3 * std::sin(3.0 * std::log(a0))); }
double Capped(double a0) { return Cubic(std::min(a0, 1e-5)); }

TEST(ApertureSearch, ProportionalCurveNeedsOneCubeRootStep) {
  // From a start 10x too large: k is 1000x too large, the cube-root step lands on the exact a0
  // up to the cube root's round-off.
  const double exact = std::cbrt(kTarget / kPerCubedAperture);
  const auto r = Search(10.0 * exact, {}, Cubic);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(r->converged);
  EXPECT_EQ(r->evaluations, 2);
  EXPECT_NEAR(r->best.aperture / exact, 1.0, 1e-14);
  EXPECT_NEAR(r->first.relative_error, 999.0, 1e-9);
}

TEST(ApertureSearch, OpenGapCurveConvergesBySecant) {
  ApertureSearchOptions options;
  options.tolerance = 1e-10;
  const auto r = Search(1e-5, options, OpenGap);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_TRUE(r->converged);
  // Exact root: a0 = (k/c)^(1/3) - 5 um.
  const double exact = std::cbrt(kTarget / kPerCubedAperture) - 5e-6;
  EXPECT_NEAR(r->best.aperture / exact, 1.0, 1e-10);
  EXPECT_GT(r->evaluations, 2);
  EXPECT_LE(r->evaluations, 8);  // superlinear: a linear (cube-root only) iteration needs ~20
}

TEST(ApertureSearch, WigglyMonotoneCurveConverges) {
  ApertureSearchOptions options;
  options.tolerance = 1e-10;
  for (const double start : {1e-7, 1e-5, 1e-3}) {
    const auto r = Search(start, options, Wiggly);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_TRUE(r->converged) << "start " << start;
    EXPECT_LT(r->best.relative_error, 1e-10);
    EXPECT_LE(r->evaluations, 15) << "start " << start;
  }
}

TEST(ApertureSearch, TargetAboveTheCapStopsAtTheCap) {
  ApertureSearchOptions options;
  options.max_aperture = 1e-5;  // k(a_max) = 1e-15 / 24e-3 = 4.2e-14 < target
  const auto r = Search(1e-6, options, Capped);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_FALSE(r->converged);
  EXPECT_TRUE(r->above_cap);
  EXPECT_EQ(r->best.aperture, 1e-5);
  EXPECT_NEAR(r->best.relative_error, 1.0 - Cubic(1e-5) / kTarget, 1e-12);
  EXPECT_LE(r->evaluations, 3);
}

TEST(ApertureSearch, UnreachableTargetBelowTheGapsStaysFinite) {
  // The open gaps alone give k(0) = c (5 um)^3 = 5.2e-15 > 1e-15: no a0 > 0 reaches the target.
  ApertureSearchOptions options;
  options.max_evaluations = 12;
  const auto r = SearchResidualAperture(1e-15, 1e-5, options,
                                        [](double a0) -> Result<double> { return OpenGap(a0); });
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_FALSE(r->converged);
  EXPECT_EQ(r->evaluations, 12);
  EXPECT_GT(r->best.aperture, 0.0);
  EXPECT_TRUE(std::isfinite(r->best.relative_error));
  EXPECT_NEAR(r->best.permeability, OpenGap(0.0), 1e-3 * OpenGap(0.0));
}

TEST(ApertureSearch, ErrorsOfTheEvaluationStopTheSearch) {
  int calls = 0;
  const auto r = SearchResidualAperture(kTarget, 1e-5, {}, [&](double) -> Result<double> {
    return ++calls == 2 ? Result<double>(Cancelled("stop")) : Result<double>(1e-14);
  });
  EXPECT_EQ(r.status().code(), StatusCode::kCancelled);
  EXPECT_EQ(calls, 2);
  const auto bad =
      SearchResidualAperture(kTarget, 1e-5, {}, [](double) -> Result<double> { return 0.0; });
  EXPECT_EQ(bad.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(Search(-1.0, {}, Cubic).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace seep::core
