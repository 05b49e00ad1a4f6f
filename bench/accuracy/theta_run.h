// Runs a transient scene's network with ImplicitSolver at a chosen theta (physics.md §4.5), for
// the schemes a SceneSpec cannot select yet (Crank–Nicolson: theta = 1/2). The network is the one
// Simulation::Create builds (BuildSceneNetwork) and the stepping is Simulation's: dt = dt_factor x
// dt_crit, ceil(t_end / dt) steps, the last one shortened to land on t_end. Timed like
// RunTimed (timed_scene.h): only the steps (the solver's first step pays for its analysis and
// factorization, as in Simulation::Run), best of a few repeats, each from a fresh copy of the
// network and a fresh solver.
#pragma once

#include <cstdint>
#include <vector>

#include "seep/core/scene/scene_spec.h"
#include "seep/core/status.h"

namespace seep::bench {

struct TimedThetaRun {
  std::vector<double> pressure;  // per FlowNetwork node, after the last step of the last repeat
  std::uint64_t steps = 0;
  double wall_s = 0.0;   // fastest run of the steps
  double setup_s = 0.0;  // BuildSceneNetwork, once
};

// The scene must be transient (its solver.kind and dt_factor give the step; kind is ignored
// beyond that: theta chooses the scheme).
core::Result<TimedThetaRun> RunThetaTimed(const core::SceneSpec& scene, double theta,
                                          double min_total_s = 0.2, int min_repeats = 3,
                                          int max_repeats = 30);

// The number of steps RunThetaTimed takes (for the bench's cost cap), or 0 on error.
std::uint64_t ThetaRunSteps(const core::SceneSpec& scene);

}  // namespace seep::bench
