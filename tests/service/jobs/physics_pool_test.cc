// PhysicsPool: tasks run off the caller's thread with the pool's core thread count, the queue is
// bounded, an abandoned task that has not started never runs, and a task's exception reaches its
// caller.
#include "jobs/physics_pool.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <future>
#include <stdexcept>
#include <thread>

namespace seep::service {
namespace {

using std::chrono::milliseconds;

TEST(PhysicsPool, RunsTasksOffTheCallersThreadWithItsCoreThreadCount) {
  omp_set_num_threads(1);  // the caller's own count must not leak into the pool
  PhysicsPool pool(/*threads=*/1, /*core_threads=*/3, /*max_waiting=*/4);
  EXPECT_EQ(pool.core_threads(), 3);
  int threads_seen = 0;
  int team_size = 0;
  std::thread::id ran_on;
  auto ticket = pool.Post([&] {
    threads_seen = omp_get_max_threads();
#pragma omp parallel
    {
#pragma omp single
      team_size = omp_get_num_threads();
    }
    ran_on = std::this_thread::get_id();
  });
  ASSERT_NE(ticket, nullptr);
  ASSERT_TRUE(ticket->WaitFor(milliseconds(10000)));
  EXPECT_EQ(threads_seen, 3);
  EXPECT_EQ(team_size, 3);
  EXPECT_NE(ran_on, std::this_thread::get_id());
  EXPECT_EQ(pool.tasks_run(), 1u);
}

TEST(PhysicsPool, BoundsTheWaitingTasksAndSkipsAbandonedOnes) {
  PhysicsPool pool(/*threads=*/1, /*core_threads=*/1, /*max_waiting=*/1);
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<bool> started{false};
  auto busy = pool.Post([&] {
    started = true;
    released.wait();
  });
  ASSERT_NE(busy, nullptr);
  while (!started) std::this_thread::yield();
  std::atomic<bool> abandoned_ran{false};
  auto waiting = pool.Post([&] { abandoned_ran = true; });
  ASSERT_NE(waiting, nullptr);
  EXPECT_EQ(pool.Post([] {}), nullptr) << "one waiting task is the limit";
  EXPECT_FALSE(waiting->WaitFor(milliseconds(20)));
  waiting->Abandon();
  // An abandoned task holds no place: another may wait now.
  std::atomic<bool> next_ran{false};
  auto next = pool.Post([&] { next_ran = true; });
  ASSERT_NE(next, nullptr);
  release.set_value();
  ASSERT_TRUE(busy->WaitFor(milliseconds(10000)));
  ASSERT_TRUE(next->WaitFor(milliseconds(10000)));
  EXPECT_TRUE(next_ran);
  EXPECT_FALSE(abandoned_ran);
  EXPECT_EQ(pool.tasks_run(), 2u);
}

TEST(PhysicsPool, ATasksExceptionReachesItsCaller) {
  PhysicsPool pool(1, 1, 4);
  auto ticket = pool.Post([] { throw std::runtime_error("boom"); });
  ASSERT_NE(ticket, nullptr);
  EXPECT_THROW(ticket->WaitFor(milliseconds(10000)), std::runtime_error);
  // The pool goes on.
  auto after = pool.Post([] {});
  ASSERT_NE(after, nullptr);
  EXPECT_TRUE(after->WaitFor(milliseconds(10000)));
}

}  // namespace
}  // namespace seep::service
