// EndingSlot: a worker's previous job's end runs beside the worker, one at a time, in the order
// handed, and none is lost when the slot goes.
#include "jobs/ending_slot.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

namespace seep::service {
namespace {

using namespace std::chrono_literals;

TEST(EndingSlot, HandReturnsAtOnceAndTheNextHandWaitsForThePreviousEnding) {
  EndingSlot slot;
  std::atomic<bool> release{false};
  std::atomic<bool> first_done{false};
  std::mutex order_mutex;
  std::vector<int> order;
  slot.Hand([&] {
    while (!release) std::this_thread::sleep_for(1ms);
    std::lock_guard lock(order_mutex);
    order.push_back(1);
    first_done = true;
  });
  // The first ending is held: the worker is free (Hand returned) while it waits.
  std::atomic<bool> second_handed{false};
  std::jthread worker([&] {
    slot.Hand([&] {
      std::lock_guard lock(order_mutex);
      order.push_back(2);
    });
    second_handed = true;
  });
  std::this_thread::sleep_for(50ms);
  EXPECT_FALSE(second_handed) << "a second ending was taken while the first still ran";
  release = true;
  worker.join();
  EXPECT_TRUE(first_done) << "Hand returned before the previous ending had run";
  slot.Drain();
  std::lock_guard lock(order_mutex);
  EXPECT_EQ(order, (std::vector<int>{1, 2}));
}

TEST(EndingSlot, DestroyingTheSlotRunsThePendingEndingFirst) {
  std::atomic<int> ran{0};
  {
    EndingSlot slot;
    slot.Hand([&] {
      std::this_thread::sleep_for(30ms);
      ++ran;
    });
    slot.Hand([&] { ++ran; });  // taken once the first has run, and still pending below
  }
  EXPECT_EQ(ran, 2);
}

}  // namespace
}  // namespace seep::service
