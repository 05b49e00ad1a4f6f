// Servo wall: a stack of three disks between a fixed floor and a servo-controlled lid reaches
// the target confining stress (lid contact force / lid length), and the floor carries the same
// force (static equilibrium of the stack, no gravity).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dem_test_util.h"
#include "seep/core/dem/servo_wall.h"

namespace seep::core {
namespace {

using dem_test::MakeContacts;
using dem_test::MakeDisks;
using dem_test::RunWithServo;

TEST(DemServoWall, ReachesTargetStress) {
  DemParticles p = MakeDisks({{0.0, 0.5, 0.5}, {0.0, 1.5, 0.5}, {0.0, 2.5, 0.5}}, 1.0);
  DemContactSettings settings;
  settings.law.kn = 1.0e5;
  settings.law.kt = 2.0e4;
  settings.law.friction = 0.5;
  settings.law.damping_mode = NormalDampingMode::kCriticalRatio;
  settings.law.damping_ratio = 0.7;
  settings.skin = 0.05;
  DemContactForces contacts = MakeContacts(settings);
  std::vector<DemWall> walls{*MakeWall(0.0, 0.0, 0.0, 1.0), *MakeWall(0.0, 3.02, 0.0, -1.0)};
  ServoWallSettings servo;
  servo.target_stress = 500.0;
  servo.length = 2.0;
  servo.gain_fraction = 0.3;
  servo.max_speed = 1.0;
  ASSERT_TRUE(ValidateServoWallSettings(servo).ok());
  DemCounters counters;
  RunWithServo(&p, &walls, &contacts, servo, 1, 1.0e-5, 60000, &counters);
  ASSERT_FALSE(HasFatalFailure());
  const double target_force = servo.target_stress * servo.length;  // 1000
  // Converged: the servo is a first-order loop (each step removes gain_fraction of the error),
  // damped by the contacts' critical ratio 0.7; after 60000 steps the residual is far below
  // 1e-4 of the target.
  EXPECT_NEAR(contacts.wall_loads()[1].normal_force / servo.length, servo.target_stress,
              1e-4 * servo.target_stress);
  EXPECT_NEAR(contacts.wall_loads()[0].normal_force, target_force, 1e-4 * target_force);
  EXPECT_EQ(contacts.wall_loads()[1].contact_count, 1);
  EXPECT_EQ(counters.servo_updates, 60000u);
}

TEST(DemServoWall, SpeedFollowsTheGainLaw) {
  ServoWallSettings s;
  s.target_stress = 100.0;
  s.length = 2.0;
  s.gain_fraction = 0.5;
  s.max_speed = 10.0;
  DemWallLoad load;
  load.normal_force = 300.0;  // measured 150 > target: back off
  load.stiffness_sum = 1.0e5;
  load.contact_count = 1;
  const double dt = 1e-4;
  // G = 0.5 * 2 / (1e5 * 1e-4 + 0) = 0.1; v = 0.1 * (100 - 150) = -5.
  EXPECT_DOUBLE_EQ(ServoWallSpeed(s, load, dt), -5.0);
  load.damping_sum = 10.0;  // G = 1 / (10 + 10) = 0.05; v = 0.05 * (100 - 150) = -2.5
  EXPECT_DOUBLE_EQ(ServoWallSpeed(s, load, dt), -2.5);
  load.normal_force = 0.0;  // measured 0: v = 0.05 * 100 = +5
  EXPECT_DOUBLE_EQ(ServoWallSpeed(s, load, dt), 5.0);
  load.damping_sum = 0.0;  // v = 0.1 * 100 = +10, at the cap
  EXPECT_DOUBLE_EQ(ServoWallSpeed(s, load, dt), 10.0);
  load.stiffness_sum = 0.0;  // no contact, no first-contact stiffness: advance at max speed
  EXPECT_DOUBLE_EQ(ServoWallSpeed(s, load, dt), 10.0);
}

// Without contacts the wall takes its first contact's gain: the speed is the same whether a disk
// touches it by a hair or not at all (it jumped to max_speed, an ulp deciding which).
TEST(DemServoWall, SpeedDoesNotJumpWhenTheFirstContactForms) {
  ServoWallSettings s;
  s.target_stress = 30.0;
  s.length = 2.0;
  s.gain_fraction = 0.5;
  s.max_speed = 10.0;
  s.first_contact_stiffness = 1.0e5;
  const double dt = 1e-4;
  DemWallLoad touching;
  touching.normal_force = 1e-12;
  touching.stiffness_sum = 1.0e5;
  touching.contact_count = 1;
  const DemWallLoad apart;
  // G = 0.5 * 2 / (1e5 * 1e-4) = 0.1; v = 0.1 * 30 = 3, below the cap.
  EXPECT_NEAR(ServoWallSpeed(s, touching, dt), 3.0, 1e-12);
  EXPECT_NEAR(ServoWallSpeed(s, apart, dt), 3.0, 1e-12);
}

}  // namespace
}  // namespace seep::core
