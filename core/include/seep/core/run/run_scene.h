// RunScene: builds a scene's Simulation and runs it to the end in one call — for tests, benches
// and callers that need no checkpoints. The job service drives Simulation itself.
#pragma once

#include "seep/core/run/simulation.h"
#include "seep/core/spec/scene_spec.h"
#include "seep/core/status.h"

namespace seep::core {

Result<RunReport> RunScene(const SceneSpec& scene, const RunControl& control);

}  // namespace seep::core
