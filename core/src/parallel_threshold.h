// When a loop of the core goes parallel: below this many items an OpenMP region costs more than
// it saves (and on a loaded machine a barrier can cost far more). Every parallel loop of the core
// writes per-item results only, or sums integers, so taking the serial path never changes a
// result bit: runs are bit-identical on any thread count.
#pragma once

#include <omp.h>

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
// 3 % of its time). A loop of a line or two is written twice (a parallel for and a plain one); a
// longer block goes through RunOnCoreThreads. The DEM's loops and the vectorised coefficient,
// aperture and volume-change passes still use the clause (see RunOnCoreThreads for why).
inline bool OnTeam(std::ptrdiff_t n) { return n >= kMinParallelItems && omp_get_max_threads() > 1; }

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
