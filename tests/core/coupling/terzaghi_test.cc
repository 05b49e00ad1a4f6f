// Terzaghi consolidation reference (docs/physics.md §3.4): the table of U(Tv) and u/u0, and the
// coupled parameters c_v and u0 with a compressible fluid.
#include "seep/core/reference/terzaghi.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace seep::core {
namespace {

struct Row {
  double tv;
  double u;
  double ratio[4];  // u/u0 at z/H = 0.25, 0.5, 0.75, 1.0
};

// docs/physics.md §3.4, computed by research/scripts/tables.py.
constexpr Row kTable[] = {
    {0.008, 0.10093, {0.9519, 0.9999, 1.0000, 1.0000}},
    {0.02, 0.15958, {0.7887, 0.9876, 0.9998, 1.0000}},
    {0.05, 0.25231, {0.5708, 0.8862, 0.9822, 0.9969}},
    {0.1, 0.35682, {0.4238, 0.7357, 0.9013, 0.9493}},
    {0.197, 0.50034, {0.3046, 0.5575, 0.7214, 0.7777}},
    {0.2, 0.50409, {0.3021, 0.5532, 0.7162, 0.7723}},
    {0.3, 0.61324, {0.2329, 0.4298, 0.5609, 0.6068}},
    {0.5, 0.76395, {0.1419, 0.2622, 0.3426, 0.3708}},
    {0.848, 0.89998, {0.0601, 0.1111, 0.1452, 0.1571}},
    {1.0, 0.93126, {0.0413, 0.0764, 0.0998, 0.1080}},
    {2.0, 0.99417, {0.0035, 0.0065, 0.0085, 0.0092}},
};

// The table is rounded to 5 decimals (U) and 4 (u/u0): the exact values lie within half a unit
// of the last digit, which is the tolerance (plus 1e-12 for our own round-off). That is tighter
// than the 1e-4 asked for.
TEST(Terzaghi, MatchesReferenceTable) {
  for (const Row& row : kTable) {
    SCOPED_TRACE(testing::Message() << "Tv = " << row.tv);
    EXPECT_NEAR(DegreeOfConsolidation(row.tv), row.u, 0.5e-5 + 1e-12);
    const double depths[4] = {0.25, 0.5, 0.75, 1.0};
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(ExcessPressureRatio(depths[k], row.tv), row.ratio[k], 0.5e-4 + 1e-12)
          << "z/H = " << depths[k];
    }
  }
}

// The Fourier and image series are the same function: where both converge (all Tv > 0) they
// agree to round-off of their ~10-30 terms (1e-13 absolute).
TEST(Terzaghi, FourierAndImageSeriesAgree) {
  for (double tv : {0.005, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0}) {
    SCOPED_TRACE(testing::Message() << "Tv = " << tv);
    EXPECT_NEAR(terzaghi_series::DegreeOfConsolidationFourier(tv),
                terzaghi_series::DegreeOfConsolidationImages(tv), 1e-13);
    for (double z : {0.1, 0.3, 0.5, 0.9, 1.0}) {
      EXPECT_NEAR(terzaghi_series::ExcessPressureRatioFourier(z, tv),
                  terzaghi_series::ExcessPressureRatioImages(z, tv), 1e-13)
          << "z/H = " << z;
    }
  }
}

// Limits: U(0) = 0, U -> 1; the early-time law U = 2 sqrt(Tv/pi) holds while the far boundary
// is unfelt (its correction ~ 4 sqrt(Tv) ierfc(1/sqrt(Tv)) < 1e-20 at Tv = 1e-3); the late
// one-term law U = 1 - (8/pi^2) exp(-pi^2 Tv/4) has a next term (8/(9 pi^2)) exp(-9 pi^2 Tv/4)
// ~ 2e-11 at Tv = 1.
TEST(Terzaghi, Limits) {
  const double pi = 3.14159265358979323846;
  EXPECT_EQ(DegreeOfConsolidation(0.0), 0.0);
  EXPECT_EQ(ExcessPressureRatio(0.5, 0.0), 1.0);
  EXPECT_EQ(ExcessPressureRatio(0.0, 0.3), 0.0);
  EXPECT_NEAR(DegreeOfConsolidation(1e-3), 2.0 * std::sqrt(1e-3 / pi), 1e-15);
  EXPECT_NEAR(DegreeOfConsolidation(1.0), 1.0 - 8.0 / (pi * pi) * std::exp(-pi * pi / 4.0), 3e-11);
  EXPECT_NEAR(DegreeOfConsolidation(50.0), 1.0, 1e-15);
}

// docs/physics.md §3.4, K_f-scaling table: k = 1e-12, mu = 1e-3, E_oed = 1e8, n_s = 0.2, H = 0.05.
// The printed values have 3 significant digits: tolerance half a unit of the last one.
TEST(Terzaghi, CoupledParametersWithCompressibleFluid) {
  TerzaghiParameters p;
  p.permeability = 1e-12;
  p.viscosity = 1e-3;
  p.oedometer_modulus = 1e8;
  p.storage_porosity = 0.2;
  p.drainage_length = 0.05;
  p.load_step = 1e5;
  struct Case {
    double kf, cv, u0_ratio, t1;
  };
  for (const Case& c : {Case{2.2e9, 0.0991, 0.991, 0.025}, Case{2e8, 0.0909, 0.909, 0.0275},
                        Case{2e7, 0.050, 0.50, 0.050}}) {
    SCOPED_TRACE(testing::Message() << "K_f = " << c.kf);
    p.fluid_bulk_modulus = c.kf;
    ASSERT_TRUE(ValidateTerzaghiParameters(p).ok());
    EXPECT_NEAR(ConsolidationCoefficient(p), c.cv, 0.5e-4);
    EXPECT_NEAR(InitialExcessPressure(p) / p.load_step, c.u0_ratio, 0.5e-3);
    EXPECT_NEAR(TimeForTimeFactor(p, 1.0), c.t1, 0.5e-3);
    EXPECT_NEAR(TimeFactor(p, TimeForTimeFactor(p, 0.3)), 0.3, 1e-15);
  }
  // Incompressible fluid: u0 = dsigma, c_v = k E_oed / mu; the settlement goes from 0 to
  // dsigma H / E_oed.
  p.fluid_bulk_modulus = std::numeric_limits<double>::infinity();
  ASSERT_TRUE(ValidateTerzaghiParameters(p).ok());
  EXPECT_DOUBLE_EQ(InitialExcessPressure(p), p.load_step);
  EXPECT_DOUBLE_EQ(ConsolidationCoefficient(p), 1e-12 * 1e8 / 1e-3);
  EXPECT_EQ(Settlement(p, 0.0), 0.0);
  EXPECT_NEAR(Settlement(p, 1e3), p.load_step * p.drainage_length / p.oedometer_modulus, 1e-18);
  // With compressible fluid the undrained part is immediate: s(0) = (dsigma - u0) m_v H.
  p.fluid_bulk_modulus = 2e7;
  EXPECT_NEAR(Settlement(p, 0.0), 0.5 * p.load_step * p.drainage_length / p.oedometer_modulus,
              1e-12 * p.load_step * p.drainage_length / p.oedometer_modulus);
}

TEST(Terzaghi, ValidationNamesTheField) {
  TerzaghiParameters p;
  p.permeability = 1e-12;
  p.oedometer_modulus = -1.0;
  p.drainage_length = 1.0;
  p.fluid_bulk_modulus = 1e9;
  const Status s = ValidateTerzaghiParameters(p);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("coupling.terzaghi.oedometer_modulus"), std::string::npos)
      << s.message();
}

}  // namespace
}  // namespace seep::core
