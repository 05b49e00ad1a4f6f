// The reversal guard's rule for a servo wall (core/run/reversal_guard.h), on speed sequences of
// the three kinds a servo makes: chatter between its speed limits (its gain missing stiffness:
// the guard's case), an overshoot that dies out (a stable gain above the deadbeat one), and a
// dither at its target (rounding).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "seep/core/run/reversal_guard.h"

namespace seep::core {
namespace {

// The count after `steps` steps of speed v_k = v_0 (-r)^k, `miss` of the target away each step.
std::uint32_t CountAfter(int steps, double r, double miss) {
  std::uint32_t count = 0;
  double speed = 1e-3;
  for (int k = 0; k < steps; ++k) {
    const double next = -r * speed;
    count = ReversalGuard::ServoReversals(count, speed, next, miss);
    speed = next;
  }
  return count;
}

TEST(ServoReversal, AServoChatteringAtItsSpeedLimitCountsEveryStep) {
  EXPECT_EQ(CountAfter(40, 1.0, 0.13), 40u);  // platens at +-max speed, 13 % off (87 kPa of 100)
  EXPECT_EQ(CountAfter(ReversalGuard::kServoSteps, 1.3, 0.5), ReversalGuard::kServoSteps);
}

TEST(ServoReversal, AnOvershootThatDiesOutIsNotCounted) {
  // A loop gain of 1.9 (the stiffness underestimated by 1.9): the error reverses and shrinks by
  // 0.9 a step, which 32 steps of a 100 % miss would otherwise count.
  EXPECT_EQ(CountAfter(40, 0.9, 1.0), 0u);
}

TEST(ServoReversal, ADitherAtTheTargetIsNotCounted) { EXPECT_EQ(CountAfter(40, 1.0, 1e-4), 0u); }

TEST(ServoReversal, OneStepWithoutAReversalStartsTheCountAgain) {
  std::uint32_t count = CountAfter(20, 1.0, 0.5);
  ASSERT_EQ(count, 20u);
  count = ReversalGuard::ServoReversals(count, 1e-3, 2e-3, 0.5);  // same direction
  EXPECT_EQ(count, 0u);
}

}  // namespace
}  // namespace seep::core
