// PFC-style servo control of a wall's velocity from its contact stress.
#include "seep/core/dem/servo_wall.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace seep::core {

Status ValidateServoWallSettings(const ServoWallSettings& s) {
  auto bad = [](const char* field, double v, const char* rule) {
    return InvalidArgument(std::string("dem.servo.") + field + ": must be " + rule + " (got " +
                           std::to_string(v) + ")");
  };
  if (!std::isfinite(s.target_stress)) return bad("target_stress", s.target_stress, "finite");
  if (!std::isfinite(s.length) || s.length <= 0.0) return bad("length", s.length, "finite and > 0");
  if (!(s.gain_fraction > 0.0 && s.gain_fraction <= 1.0)) {
    return bad("gain_fraction", s.gain_fraction, "in (0, 1]");
  }
  if (!std::isfinite(s.max_speed) || s.max_speed <= 0.0) {
    return bad("max_speed", s.max_speed, "finite and > 0");
  }
  return Status::Ok();
}

double ServoWallSpeed(const ServoWallSettings& s, const DemWallLoad& load, double dt) {
  // No contact: advance to find the sample, as fast as its first contact will allow.
  const double stiffness = std::max(load.stiffness_sum, s.first_contact_stiffness);
  if (stiffness <= 0.0) return s.max_speed;
  const double measured = load.normal_force / s.length;
  const double gain = s.gain_fraction * s.length / (stiffness * dt + load.damping_sum);
  return std::clamp(gain * (s.target_stress - measured), -s.max_speed, s.max_speed);
}

void ApplyServo(const ServoWallSettings& s, const DemWallLoad& load, double dt, DemWall* wall,
                DemCounters* counters) {
  const double v = ServoWallSpeed(s, load, dt);
  wall->vx = v * wall->nx;
  wall->vy = v * wall->ny;
  if (counters != nullptr) ++counters->servo_updates;
}

}  // namespace seep::core
