// The closed-form references of analytic_solutions.h against the tables of docs/physics.md
// §3.2–3.3.
#include "seep/core/reference/analytic_solutions.h"

#include <gtest/gtest.h>

#include <cmath>

namespace seep::core {
namespace {

// The tables are printed to 5 decimals: half a unit of the last digit plus round-off.
constexpr double kTableTolerance = 5.1e-6;

TEST(AnalyticSolutions, DirichletDirichletMatchesTable) {
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.1, 0.01), 0.47950, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.25, 0.02), 0.21130, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.25, 0.05), 0.42920, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.5, 0.05), 0.11384, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.75, 0.05), 0.01763, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.5, 0.1), 0.26276, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.75, 0.2), 0.18759, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.9, 1.0), 0.09999, kTableTolerance);
}

TEST(AnalyticSolutions, DirichletNoFlowMatchesTable) {
  EXPECT_NEAR(DiffusionDirichletNoFlow(0.25, 0.01), 0.07710, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletNoFlow(1.0, 0.05), 0.00313, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletNoFlow(0.75, 0.2), 0.28377, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletNoFlow(1.0, 0.5), 0.62922, kTableTolerance);
  EXPECT_NEAR(DiffusionDirichletNoFlow(0.5, 1.0), 0.92365, kTableTolerance);
}

// Images and sine series are two exact forms of the same function. The implementation uses the
// images below T = 0.05 and the series above; here each side is checked against the other form,
// summed independently (1e-13 of p1 allows for ~2000 summed terms of order 1/n).
double LongSeriesDirichletDirichlet(double xi, double T) {
  const double pi = std::acos(-1.0);
  double sum = 0.0;
  for (int n = 1; n <= 2000; ++n) sum += std::sin(n * pi * xi) / n * std::exp(-n * n * pi * pi * T);
  return 1.0 - xi - 2.0 / pi * sum;
}

double LongSeriesDirichletNoFlow(double xi, double T) {
  const double pi = std::acos(-1.0);
  double sum = 0.0;
  for (int m = 0; m <= 2000; ++m) {
    const double big_m = (2 * m + 1) * pi / 2.0;
    sum += std::sin(big_m * xi) * std::exp(-big_m * big_m * T) / big_m;
  }
  return 1.0 - 2.0 * sum;
}

double ImagesDirichletDirichlet(double xi, double T) {
  double p = 0.0;
  for (int n = 0; n < 200; ++n) {
    p += std::erfc((2.0 * n + xi) / (2.0 * std::sqrt(T))) -
         std::erfc((2.0 * n + 2.0 - xi) / (2.0 * std::sqrt(T)));
  }
  return p;
}

double ImagesDirichletNoFlow(double xi, double T) {
  double p = 0.0;
  for (int n = 0; n < 200; ++n) {
    const double sign = n % 2 == 0 ? 1.0 : -1.0;
    p += sign * (std::erfc((2.0 * n + xi) / (2.0 * std::sqrt(T))) +
                 std::erfc((2.0 * n + 2.0 - xi) / (2.0 * std::sqrt(T))));
  }
  return p;
}

TEST(AnalyticSolutions, ImagesAndSeriesAgree) {
  for (const double xi : {0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0}) {
    for (const double T : {0.005, 0.03, 0.0499}) {  // images inside, long series here
      EXPECT_NEAR(DiffusionDirichletDirichlet(xi, T), LongSeriesDirichletDirichlet(xi, T), 1e-13)
          << xi << " " << T;
      EXPECT_NEAR(DiffusionDirichletNoFlow(xi, T), LongSeriesDirichletNoFlow(xi, T), 1e-13)
          << xi << " " << T;
    }
    for (const double T : {0.05, 0.2, 2.0}) {  // series inside, images here
      EXPECT_NEAR(DiffusionDirichletDirichlet(xi, T), ImagesDirichletDirichlet(xi, T), 1e-13)
          << xi << " " << T;
      EXPECT_NEAR(DiffusionDirichletNoFlow(xi, T), ImagesDirichletNoFlow(xi, T), 1e-13)
          << xi << " " << T;
    }
  }
}

TEST(AnalyticSolutions, BoundaryAndLimitValues) {
  for (const double T : {1e-6, 0.01, 0.2, 3.0}) {
    EXPECT_NEAR(DiffusionDirichletDirichlet(0.0, T), 1.0, 1e-14) << T;
    EXPECT_NEAR(DiffusionDirichletDirichlet(1.0, T), 0.0, 1e-14) << T;
    EXPECT_NEAR(DiffusionDirichletNoFlow(0.0, T), 1.0, 1e-14) << T;
  }
  // Steady states: linear (a), uniform p1 (b); exp(-pi^2 / 4 * 30) ~ 1e-32.
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.3, 30.0), 0.7, 1e-15);
  EXPECT_NEAR(DiffusionDirichletNoFlow(0.7, 30.0), 1.0, 1e-15);
  // Early times: the semi-infinite erfc.
  EXPECT_NEAR(DiffusionDirichletDirichlet(0.02, 1e-4), std::erfc(0.02 / (2.0 * 1e-2)), 1e-15);
  EXPECT_EQ(DiffusionDirichletDirichlet(0.0, 0.0), 1.0);
  EXPECT_EQ(DiffusionDirichletDirichlet(0.5, 0.0), 0.0);
}

TEST(AnalyticSolutions, ThiemMatchesPhysicsExample) {
  // docs/physics.md §3.3: r_w = 0.01, r_e = 1, p_w = 1e5, p_e = 0, k = 1e-12, mu = 1e-3.
  EXPECT_NEAR(ThiemPressure(0.02, 0.01, 1.0, 1e5, 0.0), 84948.5, 0.05);
  EXPECT_NEAR(ThiemPressure(0.1, 0.01, 1.0, 1e5, 0.0), 50000.0, 1e-9);
  EXPECT_NEAR(ThiemPressure(0.5, 0.01, 1.0, 1e5, 0.0), 15051.5, 0.05);
  EXPECT_NEAR(ThiemFlowRate(1e-12, 1e-3, 0.01, 1.0, 1e5, 0.0), 1.364376e-4, 5e-11);
}

}  // namespace
}  // namespace seep::core
