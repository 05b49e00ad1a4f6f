// When a loop of the core goes parallel: below this many items a team run (core_team.h) costs more
// than it saves (and on a loaded machine a barrier can cost far more). Every parallel loop of the
// core writes per-item results only, or sums integers, so taking the serial path never changes a
// result bit: runs are bit-identical on any thread count.
#pragma once

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <utility>

#include "core_team.h"

namespace seep::core::internal {

// 8192 items: a coupled scene of a few hundred disks (a thousand or two pairs) took 6x longer
// with two threads than with one while other processes shared the two cores (each barrier
// waits for a descheduled thread); the 10k-disk bench bed (about 25k pairs, 18k loop contacts)
// still gains 1.5-2x.
inline constexpr std::ptrdiff_t kMinParallelItems = 8192;
// The threshold loops started from the calling thread use: kMinParallelItems, unless a test
// lowered it (SetMinParallelItemsForThisThread, threads.h) so that small scenes take the team
// paths too and a thread-count test over them checks those paths.
inline thread_local std::ptrdiff_t tl_min_parallel_items = kMinParallelItems;
inline std::ptrdiff_t MinParallelItems() { return tl_min_parallel_items; }

// The calling thread's core threads (SetCoreThreadsForThisThread; OpenMP's nthreads setting, which
// also takes OMP_NUM_THREADS): the size of its team (core_team.h).
inline int CoreThreads() { return omp_get_max_threads(); }

// Whether a loop over `n` items goes to a team of the calling thread's core threads; when not,
// it runs on the calling thread with no team at all.
inline bool OnTeam(std::ptrdiff_t n) { return n >= MinParallelItems() && CoreThreads() > 1; }

// Runs `range(begin, end)` over [0, n): once per team member on its share when OnTeam(n), else
// once over [0, n) on the calling thread. `range` is a loop over its bounds, best a call of a
// function whose pointer parameters are __restrict, with `#pragma omp simd` where the loop
// vectorises: the closure then costs nothing (see RunOnCoreThreads).
template <class Range>
inline void ForEachShare(std::ptrdiff_t n, Range&& range) {
  if (!OnTeam(n)) {
    range(std::ptrdiff_t{0}, n);
    return;
  }
  RunOnTeam(CoreThreads(), [&](const TeamMember& member) {
    const auto [begin, end] = member.Share(n);
    range(begin, end);
  });
}

// The same for a range that returns a count of whole numbers (in a double): their sum, exact in
// any order, so the same on any thread count.
template <class Range>
inline double SumOverShares(std::ptrdiff_t n, Range&& range) {
  if (!OnTeam(n)) return range(std::ptrdiff_t{0}, n);
  std::atomic<double> sum{0.0};
  RunOnTeam(CoreThreads(), [&](const TeamMember& member) {
    const auto [begin, end] = member.Share(n);
    sum.fetch_add(range(begin, end), std::memory_order_relaxed);
  });
  return sum.load(std::memory_order_relaxed);
}

// The same for a range that returns a maximum (of values >= 0): exact in any order.
template <class Range>
inline double MaxOverShares(std::ptrdiff_t n, Range&& range) {
  if (!OnTeam(n)) return range(std::ptrdiff_t{0}, n);
  std::atomic<double> largest{0.0};
  RunOnTeam(CoreThreads(), [&](const TeamMember& member) {
    const auto [begin, end] = member.Share(n);
    const double mine = range(begin, end);
    double seen = largest.load(std::memory_order_relaxed);
    while (mine > seen && !largest.compare_exchange_weak(seen, mine, std::memory_order_relaxed)) {
    }
  });
  return largest.load(std::memory_order_relaxed);
}

// Runs `body(member)`, whose loops take the member's share (member.Share) or a stride of blocks,
// on a team when OnTeam(n), else on this thread as a team of one (TeamMember::Solo: its loops
// then run every item in order). Not for short vectorised loops: reached through the closure,
// their pointers no longer vectorise as well (GCC 12: the aperture and coefficient passes lost
// half their packed arithmetic and the coupled step 6-9 % when they were written this way).
template <class Body>
inline void RunOnCoreThreads(std::ptrdiff_t n, Body&& body) {
  if (OnTeam(n)) {
    RunOnTeam(CoreThreads(), body);
  } else {
    body(TeamMember::Solo());
  }
}

}  // namespace seep::core::internal
