// The reference order of one DEM step (see dem_step.h).
#include "seep/core/dem/dem_step.h"

namespace seep::core {

Status ComputeDemForces(DemParticles* particles, const std::vector<DemWall>& walls,
                        DemContactForces* contacts, const DemStepOptions& options,
                        DemCounters* counters) {
  SEEP_RETURN_IF_ERROR(contacts->SetForces(particles, walls, options.dt, counters));
  if (options.gravity_x != 0.0 || options.gravity_y != 0.0) {
    AddGravity(particles, options.gravity_x, options.gravity_y, counters);
  }
  if (options.local_damping > 0.0) {
    ApplyLocalDamping(particles, options.local_damping, options.dt, counters);
  }
  return Status::Ok();
}

Status DemStep(DemParticles* particles, std::vector<DemWall>* walls, DemContactForces* contacts,
               const DemStepOptions& options, DemCounters* counters) {
  if (!(options.dt > 0.0)) return InvalidArgument("dem.step.dt: must be > 0");
  IntegrateFirstHalf(particles, options.dt, counters);
  MoveWalls(walls, options.dt);
  SEEP_RETURN_IF_ERROR(ComputeDemForces(particles, *walls, contacts, options, counters));
  IntegrateSecondHalf(particles, options.dt, counters);
  return Status::Ok();
}

}  // namespace seep::core
