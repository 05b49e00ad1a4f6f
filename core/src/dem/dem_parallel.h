// The DEM's parallel loops follow the core's threshold (parallel_threshold.h).
#pragma once

#include "../parallel_threshold.h"

namespace seep::core::dem_internal {

using internal::CoreThreads;
using internal::ForEachShare;
using internal::kMinParallelItems;
using internal::MaxOverShares;
using internal::MinParallelItems;
using internal::OnTeam;
using internal::RunOnTeam;
using internal::SumOverShares;
using internal::TeamMember;

}  // namespace seep::core::dem_internal
