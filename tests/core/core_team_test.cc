// The core's thread team (core/src/core_team.h): who runs, the shares, the barrier's ordering,
// nesting, size changes, exceptions, several calling threads, and a forked child. Also run under
// ThreadSanitizer (label concurrency), which checks that the team's atomics order every write a
// member makes before the barrier and before the end of the run.
#include "core_team.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

namespace seep::core::internal {
namespace {

TEST(CoreTeam, EveryMemberRunsOnceAndTheSharesTile) {
  for (const int members : {2, 3, 5}) {
    std::vector<int> runs(static_cast<std::size_t>(members), 0);
    std::vector<std::pair<std::ptrdiff_t, std::ptrdiff_t>> shares(runs.size());
    std::atomic<int> wrong_size{0};
    const std::ptrdiff_t n = 1001;
    RunOnTeam(members, [&](const TeamMember& member) {
      if (member.size() != members) wrong_size.fetch_add(1);
      ++runs[static_cast<std::size_t>(member.index())];
      shares[static_cast<std::size_t>(member.index())] = member.Share(n);
    });
    EXPECT_EQ(wrong_size.load(), 0);
    std::ptrdiff_t next = 0;
    for (int m = 0; m < members; ++m) {
      EXPECT_EQ(runs[static_cast<std::size_t>(m)], 1) << "member " << m;
      EXPECT_EQ(shares[static_cast<std::size_t>(m)].first, next) << "member " << m;
      const std::ptrdiff_t size =
          shares[static_cast<std::size_t>(m)].second - shares[static_cast<std::size_t>(m)].first;
      EXPECT_TRUE(size == n / members || size == n / members + 1) << "member " << m;
      next = shares[static_cast<std::size_t>(m)].second;
    }
    EXPECT_EQ(next, n);
  }
}

// Each round every member writes its slot, meets the others, and reads all slots: a barrier that
// let a member through early, or a generation mixed up between rounds, shows as a stale slot.
TEST(CoreTeam, BarrierMakesEveryWriteVisible) {
  constexpr int kMembers = 3;
  constexpr int kRounds = 2000;
  std::vector<long> slot(kMembers, -1);
  std::atomic<int> stale{0};
  RunOnTeam(kMembers, [&](const TeamMember& member) {
    for (int round = 0; round < kRounds; ++round) {
      slot[static_cast<std::size_t>(member.index())] = round * kMembers + member.index();
      member.Barrier();
      for (int m = 0; m < kMembers; ++m) {
        if (slot[static_cast<std::size_t>(m)] != round * kMembers + m) stale.fetch_add(1);
      }
      member.Barrier();  // nobody overwrites a slot before every member has read it
    }
  });
  EXPECT_EQ(stale.load(), 0);
}

// What the members wrote is the caller's to read when the run returns, run after run.
TEST(CoreTeam, RunsEndAfterEveryMemberAndFollowEachOther) {
  constexpr int kMembers = 2;
  std::vector<long> cell(1000, 0);
  for (long run = 1; run <= 3000; ++run) {
    RunOnTeam(kMembers, [&](const TeamMember& member) {
      const auto [begin, end] = member.Share(static_cast<std::ptrdiff_t>(cell.size()));
      for (std::ptrdiff_t k = begin; k < end; ++k) cell[static_cast<std::size_t>(k)] += 1;
    });
    ASSERT_EQ(cell.front(), run);
    ASSERT_EQ(cell.back(), run);
  }
}

TEST(CoreTeam, ARunInsideARunIsATeamOfOne) {
  std::atomic<int> inner_members{0};
  std::atomic<int> inner_bad{0};
  RunOnTeam(2, [&](const TeamMember&) {
    RunOnTeam(4, [&](const TeamMember& inner) {
      inner_members.fetch_add(1);
      if (inner.index() != 0 || inner.size() != 1) inner_bad.fetch_add(1);
      inner.Barrier();  // a team of one passes straight through
    });
  });
  EXPECT_EQ(inner_members.load(), 2);  // once on each outer member
  EXPECT_EQ(inner_bad.load(), 0);
}

TEST(CoreTeam, TheTeamFollowsTheSizeAskedFor) {
  for (const int members : {2, 4, 1, 3, 2}) {
    std::atomic<int> ran{0};
    RunOnTeam(members, [&](const TeamMember& member) {
      EXPECT_EQ(member.size(), members);
      ran.fetch_add(1);
    });
    EXPECT_EQ(ran.load(), members);
  }
}

TEST(CoreTeam, TheCallersExceptionComesBackAfterTheWorkersFinish) {
  std::atomic<int> finished{0};
  EXPECT_THROW(RunOnTeam(3,
                         [&](const TeamMember& member) {
                           if (member.index() == 0) throw std::runtime_error("member 0");
                           finished.fetch_add(1);
                         }),
               std::runtime_error);
  EXPECT_EQ(finished.load(), 2);
  // The team is usable afterwards.
  std::atomic<int> ran{0};
  RunOnTeam(3, [&](const TeamMember&) { ran.fetch_add(1); });
  EXPECT_EQ(ran.load(), 3);
}

// Each calling thread has its own team (a job service runs jobs on several threads at once).
TEST(CoreTeam, CallingThreadsHaveTheirOwnTeams) {
  constexpr int kCallers = 3;
  std::vector<long> total(kCallers, 0);
  std::vector<std::thread> callers;
  for (int c = 0; c < kCallers; ++c) {
    callers.emplace_back([&total, c] {
      std::vector<long> cell(64, 0);
      for (int run = 0; run < 500; ++run) {
        RunOnTeam(2, [&](const TeamMember& member) {
          const auto [begin, end] = member.Share(static_cast<std::ptrdiff_t>(cell.size()));
          for (std::ptrdiff_t k = begin; k < end; ++k) cell[static_cast<std::size_t>(k)] += c + 1;
          member.Barrier();
        });
      }
      for (const long v : cell) total[static_cast<std::size_t>(c)] += v;
    });
  }
  for (std::thread& caller : callers) caller.join();
  for (int c = 0; c < kCallers; ++c)
    EXPECT_EQ(total[static_cast<std::size_t>(c)], 64L * 500 * (c + 1));
}

#if !defined(__SANITIZE_THREAD__)  // ThreadSanitizer does not follow a multi-threaded fork
// A forked child's copy of the parent's team has no worker threads: the child makes its own.
TEST(CoreTeam, AForkedChildMakesItsOwnTeam) {
  std::atomic<int> ran{0};
  RunOnTeam(2, [&](const TeamMember&) { ran.fetch_add(1); });
  ASSERT_EQ(ran.load(), 2);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::atomic<int> child_ran{0};
    RunOnTeam(2, [&](const TeamMember& member) {
      child_ran.fetch_add(1);
      member.Barrier();
    });
    _exit(child_ran.load() == 2 ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}
#endif

}  // namespace
}  // namespace seep::core::internal
