// Timing of one scene (see timed_scene.h).
#include "timed_scene.h"

#include <algorithm>
#include <chrono>
#include <utility>

namespace seep::bench {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

core::Result<TimedSimulation> RunTimed(const core::SceneSpec& scene, double min_total_s,
                                       int min_repeats, int max_repeats) {
  TimedSimulation out;
  double total = 0.0;
  for (int repeat = 0; repeat < max_repeats; ++repeat) {
    if (repeat > 0 && total >= min_total_s && (repeat >= min_repeats || total >= min_total_s * 3)) {
      break;
    }
    const auto t0 = Clock::now();
    SEEP_ASSIGN_OR_RETURN(core::Simulation sim, core::Simulation::Create(scene));
    const auto t1 = Clock::now();
    SEEP_RETURN_IF_ERROR(sim.Run({}));
    const auto t2 = Clock::now();
    const double setup = Seconds(t0, t1);
    const double wall = Seconds(t1, t2);
    out.setup_s = repeat == 0 ? setup : std::min(out.setup_s, setup);
    out.wall_s = repeat == 0 ? wall : std::min(out.wall_s, wall);
    total += setup + wall;
    out.simulation.emplace(std::move(sim));
  }
  return out;
}

}  // namespace seep::bench
