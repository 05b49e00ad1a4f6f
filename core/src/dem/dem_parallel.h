// When the DEM loops go parallel: below this many items an OpenMP region costs more than it
// saves (and on a loaded machine a barrier can cost far more). Every parallel loop of the dem
// area writes per-item results only, so taking the serial path never changes a result bit.
#pragma once

#include <cstddef>

namespace seep::core::dem_internal {

inline constexpr std::ptrdiff_t kMinParallelItems = 256;

}  // namespace seep::core::dem_internal
