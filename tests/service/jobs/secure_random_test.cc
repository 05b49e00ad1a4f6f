#include "jobs/secure_random.h"

#include <gtest/gtest.h>

#include <bit>
#include <set>

namespace seep::service {
namespace {

// 20000 draws: no repeat (a collision among 64-bit values is ~1e-11 likely), and every bit is set
// in 45-55 % of them (a constant, a counter or a clock would fail both).
TEST(SecureRandom, DrawsDoNotRepeatAndEveryBitVaries) {
  constexpr int kDraws = 20000;
  std::set<std::uint64_t> seen;
  int ones[64] = {};
  for (int i = 0; i < kDraws; ++i) {
    auto value = SecureRandomU64();
    ASSERT_TRUE(value.ok()) << value.status().ToString();
    EXPECT_TRUE(seen.insert(*value).second) << "repeated " << *value;
    for (int b = 0; b < 64; ++b) ones[b] += static_cast<int>((*value >> b) & 1u);
  }
  for (int b = 0; b < 64; ++b) {
    EXPECT_GT(ones[b], kDraws * 45 / 100) << "bit " << b;
    EXPECT_LT(ones[b], kDraws * 55 / 100) << "bit " << b;
  }
}

}  // namespace
}  // namespace seep::service
