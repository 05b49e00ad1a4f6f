// When a loop of the core goes parallel: below this many items an OpenMP region costs more than
// it saves (and on a loaded machine a barrier can cost far more). Every parallel loop of the core
// writes per-item results only, or sums integers, so taking the serial path never changes a
// result bit: runs are bit-identical on any thread count.
#pragma once

#include <cstddef>

namespace seep::core::internal {

// 8192 items: a coupled scene of a few hundred disks (a thousand or two pairs) took 6x longer
// with two threads than with one while other processes shared the two cores (each barrier
// waits for a descheduled thread); the 10k-disk bench bed (about 25k pairs, 18k loop contacts)
// still gains 1.5-2x.
inline constexpr std::ptrdiff_t kMinParallelItems = 8192;

}  // namespace seep::core::internal
