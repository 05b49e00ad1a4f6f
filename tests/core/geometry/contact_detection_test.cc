// Cell-grid contact detection against the O(N^2) reference.
#include "seep/core/geometry/contact_detection.h"

#include <gtest/gtest.h>

#include <random>

#include "geometry_test_util.h"
#include "seep/core/geometry/random_packing.h"

namespace seep::core {
namespace {

// Random overlapping disks (not a packing): a harsh case for the grid, radii 0.1 .. 1.5.
Packing RandomDisks(std::size_t n, std::uint64_t seed, double box) {
  std::mt19937_64 rng(seed);
  Packing p;
  for (std::size_t k = 0; k < n; ++k) {
    const double x = UniformUnit(rng()) * box;
    const double y = UniformUnit(rng()) * box;
    p.Add(x, y, 0.1 + 1.4 * UniformUnit(rng()));
  }
  return p;
}

void ExpectSameContacts(const ContactList& got, const ContactList& want) {
  ASSERT_EQ(got.size(), want.size());
  EXPECT_EQ(got.i, want.i);
  EXPECT_EQ(got.j, want.j);
  EXPECT_EQ(got.gap, want.gap);  // same arithmetic, so bit-identical
}

TEST(ContactDetection, MatchesBruteForceOnRandomDisks) {
  const Packing p = RandomDisks(3000, 99, 80.0);
  ContactDetector detector;
  ContactList got;
  for (const double max_gap : {0.0, 0.05, 0.7, -0.05}) {
    ASSERT_TRUE(detector.Detect(p, max_gap, &got).ok());
    const ContactList want = testing::BruteForceContacts(p, max_gap);
    ASSERT_GT(want.size(), 100u);
    ExpectSameContacts(got, want);
  }
}

TEST(ContactDetection, MatchesBruteForceOnSparseClusters) {
  // Two clumps far apart: the grid must widen its cells instead of allocating a huge grid.
  Packing p = RandomDisks(400, 5, 10.0);
  const Packing far = RandomDisks(400, 6, 10.0);
  for (std::size_t k = 0; k < far.size(); ++k) p.Add(far.x[k] + 1e6, far.y[k] - 1e6, far.radius[k]);
  ContactDetector detector;
  ContactList got;
  ASSERT_TRUE(detector.Detect(p, 0.1, &got).ok());
  ExpectSameContacts(got, testing::BruteForceContacts(p, 0.1));
  EXPECT_LT(detector.MemoryBytes(), 200000u);
}

TEST(ContactDetection, RejectsBadMaxGapAndHandlesEmpty) {
  Packing p;
  EXPECT_TRUE(DetectContacts(p, 0.0).ok());
  p.Add(0, 0, 1);
  p.Add(1, 0, 0.5);
  EXPECT_FALSE(DetectContacts(p, -0.6).ok());  // below -min(radius)
  EXPECT_FALSE(DetectContacts(p, std::nan("")).ok());
  const ContactList one = DetectContacts(p, 0.0).value();
  ASSERT_EQ(one.size(), 1u);
  EXPECT_DOUBLE_EQ(one.gap[0], -0.5);
}

}  // namespace
}  // namespace seep::core
