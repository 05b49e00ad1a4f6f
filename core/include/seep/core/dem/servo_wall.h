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
// caller (the wall is infinite; the loaded length is a property of the sample). The stiffness in
// G is at least that of one contact (first_contact_stiffness, the contact law's kn), so that the
// speed does not jump when the first contact forms: whether a disk touched the wall by 1e-18 m (a
// rounding) decided between a gain-limited step and a step at max_speed, which pressed the sample
// by max_speed x dt. With first_contact_stiffness 0 a wall without contacts advances at max_speed
// (PFC's servo).
#pragma once

#include "seep/core/dem/dem_counters.h"
#include "seep/core/dem/dem_wall.h"
#include "seep/core/status.h"

namespace seep::core {

struct ServoWallSettings {
  double target_stress = 0.0;            // force per length (per unit thickness), > 0 compression
  double length = 0.0;                   // loaded wall length, > 0
  double gain_fraction = 0.5;            // in (0, 1]
  double max_speed = 0.0;                // > 0
  double first_contact_stiffness = 0.0;  // kn of one contact; 0 = advance at max_speed
};

// "dem.servo.length: must be finite and > 0 (got 0)".
Status ValidateServoWallSettings(const ServoWallSettings& settings);

// A disk this close to a wall (a fraction of its radius) counts for the servo's gain in part,
// linearly from nothing at this gap to in full at contact, so that the gain does not jump when a
// contact forms: a lattice placed exactly against a wall has contacts at overlaps of +-1e-18 m,
// which rounding decides (the translation law of the metamorphic suite found the jump). A
// millionth of the radius is far above rounding and far below the gaps a packing closes, so a
// settled sample's gain is its contacts' (a ramp of 1 % of the radius slowed the side platens of
// biaxial_shear_seepage enough to lower its peak stress by 2.5 %, outside its ulp ensemble).
inline constexpr double kServoApproachGap = 1e-6;

// What a wall's contacts carried in the last force pass (DemContactForces::wall_loads()).
struct DemWallLoad {
  double normal_force = 0.0;  // sum of contact normal forces on the wall (> 0 compression)
  // Sums of kn and of the normal viscous coefficients c over its contacts, and over the disks
  // within kServoApproachGap of it, weighted (see above).
  double stiffness_sum = 0.0;
  double damping_sum = 0.0;
  int contact_count = 0;  // disks touching it
};

// The speed along the wall's inward normal given the last load.
double ServoWallSpeed(const ServoWallSettings& settings, const DemWallLoad& load, double dt);

// Sets wall->v = ServoWallSpeed(...) * n.
void ApplyServo(const ServoWallSettings& settings, const DemWallLoad& load, double dt,
                DemWall* wall, DemCounters* counters);

}  // namespace seep::core
