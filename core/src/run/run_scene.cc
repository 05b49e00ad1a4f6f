#include "seep/core/run/run_scene.h"

namespace seep::core {

Result<RunReport> RunScene(const SceneSpec& scene, const RunControl& control) {
  SEEP_ASSIGN_OR_RETURN(Simulation sim, Simulation::Create(scene, control.logger));
  SEEP_RETURN_IF_ERROR(sim.Run(control));
  return sim.Report();
}

}  // namespace seep::core
