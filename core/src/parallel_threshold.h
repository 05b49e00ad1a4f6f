// When a loop of the core goes parallel: below this many items an OpenMP region costs more than
// it saves (and on a loaded machine a barrier can cost far more). Every parallel loop of the core
// writes per-item results only, or sums integers, so taking the serial path never changes a
// result bit: runs are bit-identical on any thread count.
#pragma once

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <utility>

namespace seep::core::internal {

// 8192 items: a coupled scene of a few hundred disks (a thousand or two pairs) took 6x longer
// with two threads than with one while other processes shared the two cores (each barrier
// waits for a descheduled thread); the 10k-disk bench bed (about 25k pairs, 18k loop contacts)
// still gains 1.5-2x.
inline constexpr std::ptrdiff_t kMinParallelItems = 8192;

// Whether a loop over `n` items goes to a team of the calling thread's core threads; when not,
// it must run without a parallel region. OpenMP's `if` clause is not enough: false, it still has
// libgomp make a team of one and end it with a futex wake, about 0.2 us and a system call a
// region. A step of a small explicit job entered one such region (1,500 a job of a sweep, about
// 3 % of its time). A loop goes through ForEachShare (or its sum and maximum forms); a block of
// orphaned `omp for` loops through RunOnCoreThreads.
inline bool OnTeam(std::ptrdiff_t n) { return n >= kMinParallelItems && omp_get_max_threads() > 1; }

// The calling team member's share of `n` items, [first, second): contiguous, in thread order, and
// of sizes that differ by one at most, like schedule(static)'s (the bounds may differ from
// libgomp's by an item; no result depends on them).
inline std::pair<std::ptrdiff_t, std::ptrdiff_t> ThreadShare(std::ptrdiff_t n) {
  const std::ptrdiff_t t = omp_get_thread_num();
  const std::ptrdiff_t team = omp_get_num_threads();
  return {n * t / team, n * (t + 1) / team};
}

// Runs `range(begin, end)` over [0, n): once per team member on its share when OnTeam(n), else
// once over [0, n) with no region. `range` is a loop over its bounds, best a call of a function
// whose pointer parameters are __restrict, with `#pragma omp simd` where the loop vectorises:
// the closure then costs nothing (see RunOnCoreThreads), and a run on one thread, or a small
// scene on any, pays no region (a team of one costs 1.2 us and a system call on the 2-core VM).
template <class Range>
inline void ForEachShare(std::ptrdiff_t n, Range&& range) {
  if (!OnTeam(n)) {
    range(std::ptrdiff_t{0}, n);
    return;
  }
#pragma omp parallel
  {
    const auto [begin, end] = ThreadShare(n);
    range(begin, end);
  }
}

// The same for a range that returns a count of whole numbers (in a double): their sum, exact in
// any order, so the same on any thread count.
template <class Range>
inline double SumOverShares(std::ptrdiff_t n, Range&& range) {
  if (!OnTeam(n)) return range(std::ptrdiff_t{0}, n);
  double sum = 0.0;
#pragma omp parallel reduction(+ : sum)
  {
    const auto [begin, end] = ThreadShare(n);
    sum += range(begin, end);
  }
  return sum;
}

// The same for a range that returns a maximum (of values >= 0): exact in any order.
template <class Range>
inline double MaxOverShares(std::ptrdiff_t n, Range&& range) {
  if (!OnTeam(n)) return range(std::ptrdiff_t{0}, n);
  double largest = 0.0;
#pragma omp parallel reduction(max : largest)
  {
    const auto [begin, end] = ThreadShare(n);
    largest = std::max(largest, range(begin, end));
  }
  return largest;
}

// Runs `body`, whose loops are orphaned `omp for` constructs, on a team when OnTeam(n), else
// inline on this thread with no region (its loops then run every iteration in order, as on a
// team of one). Not for short vectorised loops: reached through the closure, their pointers no
// longer vectorise as well (GCC 12: the aperture and coefficient passes lost half their packed
// arithmetic and the coupled step 6-9 % when they were written this way).
template <class Body>
inline void RunOnCoreThreads(std::ptrdiff_t n, Body&& body) {
  if (OnTeam(n)) {
#pragma omp parallel
    body();
  } else {
    std::forward<Body>(body)();
  }
}

}  // namespace seep::core::internal
