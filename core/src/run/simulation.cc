#include "seep/core/run/simulation.h"

#include <fmt/format.h>

#include <algorithm>

#include "seep/core/log.h"

namespace seep::core {
namespace {

void LogNetwork(const SceneSpec& scene, const SceneNetwork& net, spdlog::logger& logger) {
  if (scene.boundary.radial) {
    logger.info(
        "network: {} particles, {} contacts, {} domains, {} pipes ({} to the outer reservoir; "
        "well domain {})",
        net.packing.size(), net.contacts.size(), net.domains.num_domains(), net.flow.num_pipes(),
        net.outer_pipes, net.well_domain);
  } else {
    logger.info(
        "network: {} particles, {} contacts, {} domains, {} pipes ({} to the inlet, {} to the "
        "outlet)",
        net.packing.size(), net.contacts.size(), net.domains.num_domains(), net.flow.num_pipes(),
        net.inlet_pipes, net.outlet_pipes);
  }
}

}  // namespace

Result<Simulation> Simulation::Create(const SceneSpec& scene,
                                      std::shared_ptr<spdlog::logger> logger) {
  SEEP_RETURN_IF_ERROR(ValidateScene(scene));
  if (!logger) logger = Logger();
  const bool flow = HasFlow(scene);
  SceneNetwork net;
  if (flow) {
    SEEP_ASSIGN_OR_RETURN(net, BuildSceneNetwork(scene));
    LogNetwork(scene, net, *logger);
  } else {
    SEEP_ASSIGN_OR_RETURN(net.packing, BuildScenePacking(scene.packing));
    double radius_sum = 0.0;
    for (double r : net.packing.radius) radius_sum += r;
    net.mean_radius_m = radius_sum / static_cast<double>(net.packing.size());
  }
  SEEP_ASSIGN_OR_RETURN(std::unique_ptr<Stepper> stepper,
                        Stepper::Create(scene, std::move(net), flow));
  if (stepper->dt() > 0.0) logger->info("{}", stepper->Describe());
  return Simulation(std::move(stepper));
}

ParticleView Simulation::particles() const {
  const LiveState& s = stepper_->state();
  if (s.moves()) return ParticleView{s.particles.x, s.particles.y, s.particles.radius};
  return ViewOf(s.net.packing);
}

RunProgress Simulation::Progress() const {
  RunProgress p;
  p.step = step();
  p.time_s = time_s();
  p.fraction_done = stepper_->FractionDone();
  const StageProgram& stages = stepper_->stages();
  if (stages.active()) {
    const std::uint32_t index = std::min(stages.state().index, stages.count() - 1);
    p.stage_index = index + 1;
    p.stage_count = stages.count();
    p.stage_name = stages.Name(index);
  }
  return p;
}

Status Simulation::Run(const RunControl& control) {
  if (control.on_progress) control.on_progress(Progress());
  while (!finished()) {
    if (control.stop.stop_requested()) {
      return Cancelled(fmt::format("run stopped at step {} of {}", step(), total_steps()));
    }
    SEEP_RETURN_IF_ERROR(stepper_->Step());
    if (control.at_step_end) control.at_step_end(*this);
    if (control.on_progress && (step() % stepper_->sample_every() == 0 || finished())) {
      control.on_progress(Progress());
    }
  }
  // A finished run's report must hold numbers only: a NaN here is a failed run, named.
  return CheckMetricsFinite(stepper_->Measure());
}

RunReport Simulation::Report() const {
  const Metrics m = stepper_->Measure();
  RunReport run;
  run.metrics.assign(m.begin(), m.end());
  run.steps = step();
  run.time_s = time_s();
  run.series = series();
  return run;
}

}  // namespace seep::core
