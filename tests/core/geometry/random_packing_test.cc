// The radius-expansion generator reaches its targets, removes overlaps and is reproducible.
#include "seep/core/geometry/random_packing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "geometry_test_util.h"

namespace seep::core {
namespace {

using testing::kPi;

RandomPackingOptions BaseOptions() {
  RandomPackingOptions o;
  o.count = 400;
  o.radius_min = 0.5;
  o.radius_max = 1.0;
  o.width = 30;
  o.height = 40;
  o.seed = 42;
  return o;
}

// Checks the packing without the generator's own bookkeeping: inside the box, radii uniform in
// the scaled range, largest overlap (brute force) within tolerance.
void ExpectWellFormed(const RandomPacking& r, const RandomPackingOptions& o) {
  const Packing& p = r.packing;
  ASSERT_EQ(p.size(), static_cast<std::size_t>(o.count));
  double mean = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    EXPECT_GE(p.x[k] - p.radius[k], -1e-12);
    EXPECT_LE(p.x[k] + p.radius[k], o.width + 1e-12);
    EXPECT_GE(p.y[k] - p.radius[k], -1e-12);
    EXPECT_LE(p.y[k] + p.radius[k], o.height + 1e-12);
    EXPECT_GE(p.radius[k], r.radius_scale * o.radius_min * (1 - 1e-15));
    EXPECT_LE(p.radius[k], r.radius_scale * o.radius_max * (1 + 1e-15));
    mean += p.radius[k];
  }
  mean /= static_cast<double>(p.size());
  const ContactList overlaps = testing::BruteForceContacts(p, 0.0);
  double worst = 0.0;
  for (const double g : overlaps.gap) worst = std::max(worst, -g);
  EXPECT_LE(worst, o.overlap_tolerance * mean);
}

TEST(RandomPacking, ReachesTargetPorosity) {
  RandomPackingOptions o = BaseOptions();
  o.porosity = 0.22;
  const Result<RandomPacking> r = GenerateRandomPacking(o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ExpectWellFormed(*r, o);
  // Porosity over the box, each overlap lens counted once, recomputed here.
  double solid = 0.0;
  for (const double rad : r->packing.radius) solid += kPi * rad * rad;
  const ContactList overlaps = testing::BruteForceContacts(r->packing, 0.0);
  for (std::size_t c = 0; c < overlaps.size(); ++c) {
    const double ri = r->packing.radius[overlaps.i[c]];
    const double rj = r->packing.radius[overlaps.j[c]];
    solid -= testing::SegmentLens(ri, rj, ri + rj + overlaps.gap[c]);
  }
  const double porosity = 1 - solid / (o.width * o.height);
  // Stated tolerance: 1e-3 absolute (only the residual overlaps separate it from the target).
  EXPECT_NEAR(porosity, o.porosity, 1e-3);
  EXPECT_NEAR(r->porosity, porosity, 1e-12);
}

TEST(RandomPacking, ReachesTargetCoordination) {
  RandomPackingOptions o = BaseOptions();
  o.target = RandomPackingOptions::Target::kCoordination;
  o.coordination = 3.0;
  const Result<RandomPacking> r = GenerateRandomPacking(o);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ExpectWellFormed(*r, o);
  double mean = 0.0;
  for (const double rad : r->packing.radius) mean += rad;
  mean /= o.count;
  const ContactList contacts = testing::BruteForceContacts(r->packing, o.contact_gap_ratio * mean);
  const double z = 2.0 * static_cast<double>(contacts.size()) / o.count;
  // Stated tolerance: 0.1 (the bisection stops at the first relaxed state with Z >= target).
  EXPECT_NEAR(z, o.coordination, 0.1);
  EXPECT_GE(z, o.coordination);
  EXPECT_DOUBLE_EQ(r->coordination, z);
}

TEST(RandomPacking, SameSeedSameBits) {
  RandomPackingOptions o = BaseOptions();
  o.count = 150;
  o.width = o.height = 18;
  const RandomPacking a = GenerateRandomPacking(o).value();
  const RandomPacking b = GenerateRandomPacking(o).value();
  EXPECT_EQ(a.packing.x, b.packing.x);
  EXPECT_EQ(a.packing.y, b.packing.y);
  EXPECT_EQ(a.packing.radius, b.packing.radius);
  o.seed = 43;
  const RandomPacking c = GenerateRandomPacking(o).value();
  EXPECT_NE(a.packing.x, c.packing.x);
}

TEST(RandomPacking, UniformUnitUsesTop53Bits) {
  EXPECT_EQ(UniformUnit(0), 0.0);
  EXPECT_EQ(UniformUnit(~0ull), 1.0 - 0x1.0p-53);
  EXPECT_EQ(UniformUnit(1ull << 63), 0.5);
  EXPECT_EQ(UniformUnit((1ull << 11) - 1), 0.0);  // the low 11 bits are dropped
}

TEST(RandomPacking, RejectsBadOptionsAndImpossibleTargets) {
  RandomPackingOptions o = BaseOptions();
  o.radius_min = 2.0;
  EXPECT_EQ(GenerateRandomPacking(o).status().code(), StatusCode::kInvalidArgument);
  o = BaseOptions();
  o.porosity = 1.5;
  EXPECT_EQ(GenerateRandomPacking(o).status().code(), StatusCode::kInvalidArgument);
  o = BaseOptions();
  o.count = 120;
  o.porosity = 0.02;  // far denser than any random disk packing
  o.max_relax_iterations = 300;
  EXPECT_EQ(GenerateRandomPacking(o).status().code(), StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace seep::core
