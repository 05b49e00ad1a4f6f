// Servo control of a wall to hold a confining stress (PFC style, Itasca's "servo" FISH function).
//
// The wall's speed along its inward normal is proportional to the stress error:
//   v_n = G (sigma_target - sigma_measured),   |v_n| <= max_speed
// (measured > target: the wall backs off; measured < target: it advances into the domain), with
// the gain chosen so that in one step the wall force changes by a fraction `gain_fraction` of
// the error at most:
//   G = gain_fraction * length / (stiffness_sum * dt + damping_sum)
// where stiffness_sum is the sum of the normal stiffnesses of the wall's current contacts,
// damping_sum the sum of their viscous coefficients c (PFC's G has only the stiffness term; the
// damping term is added because the measured force contains c * v_wall: without it the loop gain
// is G c / length and a wall with viscous contacts chatters between +-max_speed once
// G c / length > 1), and
// sigma_measured = (sum of the wall's contact normal forces) / length. `length` is given by the
// caller (the wall is infinite; the loaded length is a property of the sample). A wall without
// contacts advances at max_speed.
#pragma once

#include "seep/core/dem/dem_counters.h"
#include "seep/core/dem/dem_wall.h"
#include "seep/core/status.h"

namespace seep::core {

struct ServoWallSettings {
  double target_stress = 0.0;  // force per length (per unit thickness), > 0 compression
  double length = 0.0;         // loaded wall length, > 0
  double gain_fraction = 0.5;  // in (0, 1]
  double max_speed = 0.0;      // > 0
};

// "dem.servo.length: must be finite and > 0 (got 0)".
Status ValidateServoWallSettings(const ServoWallSettings& settings);

// What a wall's contacts carried in the last force pass (DemContactForces::wall_loads()).
struct DemWallLoad {
  double normal_force = 0.0;   // sum of contact normal forces on the wall (> 0 compression)
  double stiffness_sum = 0.0;  // sum of kn over its contacts
  double damping_sum = 0.0;    // sum of the normal viscous coefficients c over its contacts
  int contact_count = 0;
};

// The speed along the wall's inward normal given the last load.
double ServoWallSpeed(const ServoWallSettings& settings, const DemWallLoad& load, double dt);

// Sets wall->v = ServoWallSpeed(...) * n.
void ApplyServo(const ServoWallSettings& settings, const DemWallLoad& load, double dt,
                DemWall* wall, DemCounters* counters);

}  // namespace seep::core
