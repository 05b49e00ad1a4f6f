// Direct theta-method runs of a scene's network (see theta_run.h).
#include "theta_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "seep/core/flow/fluid.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/time_step_limit.h"
#include "seep/core/scene/scene_network.h"

namespace seep::bench {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// As Simulation's StorageOf: the scene's storage volume, factor 1.
core::StorageModel StorageOf(const core::SceneSpec& scene) {
  core::StorageModel storage;
  storage.volume = scene.solver.storage == core::StorageVolumeKind::kPore
                       ? core::StorageVolume::kPore
                       : core::StorageVolume::kApparent;
  return storage;
}

// dt and the step count exactly as Simulation::PrepareTransient computes them.
struct Stepping {
  double dt = 0.0;
  std::uint64_t steps = 0;
};

core::Result<Stepping> SteppingOf(const core::SceneSpec& scene, const core::FlowNetwork& flow) {
  SEEP_ASSIGN_OR_RETURN(
      const core::CriticalTimeStep limit,
      core::ComputeCriticalTimeStep(flow, scene.fluid.bulk_modulus_pa, StorageOf(scene)));
  if (!std::isfinite(limit.dt_crit)) {
    return core::FailedPrecondition("theta run: no domain limits the time step");
  }
  Stepping s;
  s.dt = scene.solver.dt_factor * limit.dt_crit;
  const double end = scene.solver.end_time_s;
  s.steps = static_cast<std::uint64_t>(std::ceil(end / s.dt * (1.0 - 1e-12)));
  s.steps = std::max<std::uint64_t>(s.steps, 1);
  return s;
}

}  // namespace

core::Result<TimedThetaRun> RunThetaTimed(const core::SceneSpec& scene, double theta,
                                          double min_total_s, int min_repeats, int max_repeats) {
  TimedThetaRun out;
  const auto t0 = Clock::now();
  SEEP_ASSIGN_OR_RETURN(const core::SceneNetwork net, core::BuildSceneNetwork(scene));
  out.setup_s = Seconds(t0, Clock::now());
  SEEP_ASSIGN_OR_RETURN(const Stepping stepping, SteppingOf(scene, net.flow));
  core::ImplicitSolverOptions options;
  options.bulk_modulus = scene.fluid.bulk_modulus_pa;
  options.storage = StorageOf(scene);
  options.theta = theta;
  const double end = scene.solver.end_time_s;
  double total = 0.0;
  for (int repeat = 0; repeat < max_repeats; ++repeat) {
    if (repeat > 0 && total >= min_total_s && (repeat >= min_repeats || total >= min_total_s * 3)) {
      break;
    }
    core::FlowNetwork flow = net.flow;
    SEEP_ASSIGN_OR_RETURN(core::ImplicitSolver solver, core::ImplicitSolver::Create(options));
    const auto t1 = Clock::now();
    double time = 0.0;
    for (std::uint64_t s = 1; s <= stepping.steps; ++s) {
      const bool last = s == stepping.steps;
      const double dt = last ? std::min(end - time, stepping.dt) : stepping.dt;
      SEEP_ASSIGN_OR_RETURN(const core::FlowStepReport report, solver.Step(flow, dt));
      if (!std::isfinite(report.max_pressure) || !std::isfinite(report.min_pressure)) {
        return core::FailedPrecondition("theta run: pressure became non-finite");
      }
      time = last ? end : time + report.dt;
    }
    const double wall = Seconds(t1, Clock::now());
    out.wall_s = repeat == 0 ? wall : std::min(out.wall_s, wall);
    total += wall;
    out.steps = stepping.steps;
    out.pressure.assign(flow.pressure().begin(), flow.pressure().end());
  }
  return out;
}

std::uint64_t ThetaRunSteps(const core::SceneSpec& scene) {
  const auto net = core::BuildSceneNetwork(scene);
  if (!net.ok()) return 0;
  const auto stepping = SteppingOf(scene, net->flow);
  return stepping.ok() ? stepping->steps : 0;
}

}  // namespace seep::bench
