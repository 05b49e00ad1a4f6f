// Runs a scene through the real path (SceneSpec -> Simulation::Create -> Simulation::Run) and
// times it. Short runs are repeated, each from a fresh Simulation so that every repeat pays for
// its own factorization, and the fastest repeat is kept: the figure is the run's cost, not the
// machine's noise.
#pragma once

#include <optional>

#include "seep/core/run/simulation.h"
#include "seep/core/spec/scene_spec.h"
#include "seep/core/status.h"

namespace seep::bench {

struct TimedSimulation {
  std::optional<core::Simulation> simulation;  // the last repeat, after Run()
  double wall_s = 0.0;                         // fastest Run()
  double setup_s = 0.0;                        // fastest Create()
};

// Repeats until the runs add up to min_total_s and at least min_repeats ran (at most max_repeats
// times; a run longer than 3 min_total_s runs once). The machine may be shared: the best of a
// few repeats is what the run costs without interference.
core::Result<TimedSimulation> RunTimed(const core::SceneSpec& scene, double min_total_s = 0.2,
                                       int min_repeats = 3, int max_repeats = 30);

}  // namespace seep::bench
