#include "seep/core/flow/aperture_law.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

namespace seep::core {
namespace {

ApertureLaw Law() {
  ApertureLaw law;
  law.residual_aperture = 2e-5;
  law.reference_force = 50.0;
  law.gap_multiplier = 0.4;
  return law;
}

TEST(ApertureLaw, ContinuousAtZeroForceAndGap) {
  const ApertureLaw law = Law();
  EXPECT_DOUBLE_EQ(Aperture(law, 0.0, 0.0), law.residual_aperture);
  // Approaching F = g = 0 from the compressive side and from the open side gives a0.
  const double eps = 1e-9;
  // a0 F0/(F0 + eps) = a0 (1 - eps/F0 + ...): the jump vanishes with eps.
  EXPECT_NEAR(Aperture(law, eps, 0.0), law.residual_aperture,
              1.000001 * law.residual_aperture * eps / law.reference_force);
  EXPECT_NEAR(Aperture(law, 0.0, eps), law.residual_aperture, 1.000001 * law.gap_multiplier * eps);
  EXPECT_NEAR(Aperture(law, -eps, 0.0), law.residual_aperture, 0.0);
}

TEST(ApertureLaw, CompressiveBranchIsEquation2) {
  const ApertureLaw law = Law();
  for (const double f : {1.0, 50.0, 200.0, 1e4}) {
    const double expected = law.residual_aperture * law.reference_force / (f + law.reference_force);
    EXPECT_DOUBLE_EQ(Aperture(law, f, 0.0), expected);
    // The gap is ignored under compression.
    EXPECT_DOUBLE_EQ(Aperture(law, f, 1e-3), expected);
  }
  EXPECT_DOUBLE_EQ(Aperture(law, law.reference_force, 0.0), 0.5 * law.residual_aperture);
}

TEST(ApertureLaw, OpenBranchIsEquation3) {
  const ApertureLaw law = Law();
  for (const double g : {0.0, 1e-6, 1e-4}) {
    EXPECT_DOUBLE_EQ(Aperture(law, 0.0, g), law.residual_aperture + law.gap_multiplier * g);
    EXPECT_DOUBLE_EQ(Aperture(law, -3.0, g), law.residual_aperture + law.gap_multiplier * g);
  }
  // An overlap without compression counts as a zero gap.
  EXPECT_DOUBLE_EQ(Aperture(law, 0.0, -1e-6), law.residual_aperture);
}

TEST(ApertureLaw, ClampsAtMaxAperture) {
  ApertureLaw law = Law();
  law.max_aperture = 1e-4;
  EXPECT_DOUBLE_EQ(Aperture(law, 0.0, 1.0), 1e-4);
  EXPECT_DOUBLE_EQ(Aperture(law, 0.0, 1e-5), law.residual_aperture + law.gap_multiplier * 1e-5);
}

TEST(ApertureLaw, FillsAperturesAndCubicLawConductances) {
  const ApertureLaw law = Law();
  const double mu = 1e-3;
  const std::vector<double> force{100.0, 0.0, -5.0};
  const std::vector<double> gap{0.0, 0.0, 2e-5};
  const std::vector<double> length{2e-3, 1.5e-3, 3e-3};
  std::vector<double> a(3), c(3);
  ASSERT_TRUE(FillAperturesAndConductances(law, mu, force, gap, length, a, c).ok());
  for (int p = 0; p < 3; ++p) {
    EXPECT_DOUBLE_EQ(a[p], Aperture(law, force[p], gap[p]));
    EXPECT_DOUBLE_EQ(c[p], a[p] * a[p] * a[p] / (12.0 * mu * length[p]));
  }
}

TEST(ApertureLaw, RejectsBadInputsNamingTheField) {
  ApertureLaw law = Law();
  law.residual_aperture = 0.0;
  Status s = ValidateApertureLaw(law);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("residual_aperture"), std::string::npos) << s.message();

  law = Law();
  std::vector<double> f{1.0, 2.0}, g{0.0, 0.0}, len{1e-3, 0.0}, a(2), c(2);
  s = FillAperturesAndConductances(law, 1e-3, f, g, len, a, c);
  EXPECT_NE(s.message().find("length[1]"), std::string::npos) << s.message();
  std::vector<double> short_a(1);
  s = FillAperturesAndConductances(law, 1e-3, f, g, len, short_a, c);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  f[0] = std::numeric_limits<double>::quiet_NaN();
  len[1] = 1e-3;
  s = FillAperturesAndConductances(law, 1e-3, f, g, len, a, c);
  EXPECT_NE(s.message().find("normal_force[0]"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace seep::core
