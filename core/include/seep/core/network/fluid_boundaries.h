// The boundaries fluid can leave a scene's network through, by name, and which flow node is
// which: what the run's fluid books (effects/fluid_ledger.h) keep one total for each of.
//
//   linear boundary   "inlet", "outlet" (the two reservoirs)
//   radial boundary   "well" (a well at fixed pressure; an injected well is a source, not a
//                     boundary), "outer" (the outer reservoir)
//   drained walls     "<side>_wall" per drained wall, in the walls effect's order
//                     ("<side>_wall_<w>" when two drained walls share a side)
//   boundary regions  "region_<name>" per pressure region, in the scene's order, after the
//                     rest (a flux region's domains are sources: what they take is injected)
// A walls-only boundary has only its drained walls (and regions).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "seep/core/network/scene_network.h"
#include "seep/core/spec/scene_spec.h"
#include "seep/core/status.h"

namespace seep::core {

// The scene's boundaries, in the order above (fixed for the run: it names report metrics).
std::vector<std::string> FluidBoundaryNames(const SceneSpec& scene);

// Per flow node of `net`: the index into FluidBoundaryNames(scene) of the boundary it is, or -1
// for a free or source domain. A fixed-pressure node that is none of them is an Internal error.
Result<std::vector<std::int32_t>> FluidBoundaryOfNodes(const SceneSpec& scene,
                                                       const SceneNetwork& net);

}  // namespace seep::core
