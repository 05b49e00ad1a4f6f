// A reference composition of the DEM pieces into one mechanical step, for the tests, the
// benchmark and as the order the step loop should follow (docs/physics.md §2.7 item 7: force-
// displacement, then the law of motion). It is not a simulation driver: the step loop owns the
// particles, walls and contact forces and may interleave its own effects (pore pressure forces,
// servos) between ComputeDemForces and the second half-kick.
#pragma once

#include <vector>

#include "seep/core/dem/dem_contacts.h"
#include "seep/core/dem/dem_counters.h"
#include "seep/core/dem/dem_integrator.h"
#include "seep/core/dem/dem_particles.h"
#include "seep/core/dem/dem_wall.h"
#include "seep/core/status.h"

namespace seep::core {

struct DemStepOptions {
  double dt = 0.0;         // > 0
  double gravity_x = 0.0;  // applied only when gravity is non-zero
  double gravity_y = 0.0;
  double local_damping = 0.0;  // alpha; 0 = off (ApplyLocalDamping not called)
};

// Sets the forces to: contacts and bonds (DemContactForces::SetForces, which also clears), then
// adds gravity (if non-zero) and applies local damping (if alpha > 0).
Status ComputeDemForces(DemParticles* particles, const std::vector<DemWall>& walls,
                        DemContactForces* contacts, const DemStepOptions& options,
                        DemCounters* counters);

// One velocity-Verlet step: first half (with the forces of the previous call), walls move,
// ComputeDemForces, second half. Call ComputeDemForces once before the first step.
Status DemStep(DemParticles* particles, std::vector<DemWall>* walls, DemContactForces* contacts,
               const DemStepOptions& options, DemCounters* counters);

}  // namespace seep::core
