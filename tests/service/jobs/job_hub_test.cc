// JobHub: a job's progress wakes the streams that follow that job and no other; record changes
// and shutdown wake them too; the number of followers is capped; publishers and followers on
// many threads at once (also run under ThreadSanitizer, label `concurrency`).
#include "jobs/job_hub.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace seep::service {
namespace {

using std::chrono::milliseconds;

TEST(JobHub, ProgressOfAnotherJobDoesNotWakeAFollower) {
  JobHub hub;
  const auto follower = hub.Follow("a");
  ASSERT_TRUE(follower.has_value());
  const JobHub::Versions seen = follower->versions();
  std::atomic<bool> stop{false};
  std::thread publisher([&] {
    for (std::uint64_t step = 0; !stop; ++step) {
      hub.Publish("b", JobProgress::At(step, 0.0, 0.5, 0.0));
      std::this_thread::sleep_for(milliseconds(1));
    }
  });
  const auto start = std::chrono::steady_clock::now();
  const JobHub::Versions after = follower->WaitForChange(seen, milliseconds(300));
  const auto waited = std::chrono::steady_clock::now() - start;
  stop = true;
  publisher.join();
  EXPECT_EQ(after, seen);  // timed out: b's progress never reached a's channel
  EXPECT_GE(waited, milliseconds(250));
  EXPECT_FALSE(follower->live().has_value());
}

TEST(JobHub, ItsOwnProgressAndRecordChangesWakeAFollower) {
  JobHub hub;
  const auto follower = hub.Follow("a");
  ASSERT_TRUE(follower.has_value());
  JobHub::Versions seen = follower->versions();
  std::thread publisher([&] {
    std::this_thread::sleep_for(milliseconds(20));
    hub.Publish("a", JobProgress::At(7, 1.5, 0.25, 3.0));
  });
  JobHub::Versions now = follower->WaitForChange(seen, std::chrono::seconds(10));
  publisher.join();
  EXPECT_NE(now.progress, seen.progress);
  EXPECT_EQ(now.record, seen.record);
  ASSERT_TRUE(follower->live().has_value());
  EXPECT_EQ(follower->live()->step, 7u);

  seen = now;
  hub.RecordChanged("a");
  now = follower->WaitForChange(seen, std::chrono::seconds(10));
  EXPECT_NE(now.record, seen.record);

  seen = now;
  hub.Finished("a");
  now = follower->WaitForChange(seen, std::chrono::seconds(10));
  EXPECT_NE(now.record, seen.record);
  EXPECT_FALSE(follower->live().has_value());
  EXPECT_FALSE(hub.Live("a").has_value());
}

TEST(JobHub, CloseEndsEveryWait) {
  JobHub hub;
  const auto follower = hub.Follow("a");
  ASSERT_TRUE(follower.has_value());
  std::thread closer([&] {
    std::this_thread::sleep_for(milliseconds(20));
    hub.Close();
  });
  const auto start = std::chrono::steady_clock::now();
  (void)follower->WaitForChange(follower->versions(), std::chrono::seconds(30));
  closer.join();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  EXPECT_TRUE(hub.closed());
}

TEST(JobHub, FollowersAreCappedAndCounted) {
  JobHub hub;
  {
    auto first = hub.Follow("a", /*max_followers=*/2);
    auto second = hub.Follow("b", 2);
    ASSERT_TRUE(first && second);
    EXPECT_EQ(hub.followers(), 2);
    EXPECT_FALSE(hub.Follow("c", 2).has_value());
  }
  EXPECT_EQ(hub.followers(), 0);
  EXPECT_TRUE(hub.Follow("c", 2).has_value());
}

// Many publishers and followers of a few jobs at once: every follower sees its job's last step.
TEST(JobHub, ConcurrentPublishersAndFollowersSeeTheirOwnJobsProgress) {
  JobHub hub;
  constexpr int kJobs = 4;
  constexpr int kFollowersPerJob = 3;
  constexpr std::uint64_t kSteps = 2000;
  std::vector<std::thread> threads;
  std::atomic<int> saw_last{0};
  std::atomic<bool> wrong_job{false};
  std::atomic<int> following{0};
  for (int j = 0; j < kJobs; ++j) {
    for (int f = 0; f < kFollowersPerJob; ++f) {
      threads.emplace_back([&, j] {
        const std::string id = "job-" + std::to_string(j);
        auto follower = hub.Follow(id);
        ++following;
        JobHub::Versions seen = follower->versions();
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (std::chrono::steady_clock::now() < deadline) {
          seen = follower->WaitForChange(seen, milliseconds(100));
          if (const auto live = follower->live()) {
            // Each job's progress carries its own index in time_s.
            if (live->time_s != static_cast<double>(j)) wrong_job = true;
            if (live->step == kSteps) {
              ++saw_last;
              return;
            }
          }
        }
      });
    }
  }
  while (following < kJobs * kFollowersPerJob) std::this_thread::yield();
  for (int j = 0; j < kJobs; ++j) {
    threads.emplace_back([&, j] {
      const std::string id = "job-" + std::to_string(j);
      for (std::uint64_t step = 1; step <= kSteps; ++step) {
        hub.Publish(id, JobProgress::At(step, static_cast<double>(j), 0.0, 0.0));
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(saw_last, kJobs * kFollowersPerJob);
  EXPECT_FALSE(wrong_job);
  EXPECT_EQ(hub.followers(), 0);
}

}  // namespace
}  // namespace seep::service
