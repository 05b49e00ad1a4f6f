// Finite segment walls: a disk resting on a tilted segment under gravity carries m g cos(theta)
// normal to it; a disk beyond a segment's end falls past it in free fall; an end touches like a
// disk of radius 0 and the back face like the front; a servo segment holds its stress on its
// length; bad extents are named.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "dem_test_util.h"
#include "seep/core/dem/servo_wall.h"

namespace seep::core {
namespace {

using dem_test::MakeContacts;
using dem_test::MakeDisks;
using dem_test::RunWithServo;

constexpr double kG = 9.81;
constexpr double kKn = 1.0e7;

DemContactSettings Settings(double skin) {
  DemContactSettings settings;
  settings.law.kn = kKn;
  settings.law.kt = 0.5 * kKn;
  settings.law.friction = 0.5;
  settings.law.damping_mode = NormalDampingMode::kCriticalRatio;
  settings.law.damping_ratio = 0.7;
  settings.skin = skin;
  return settings;
}

// The segment from (x0, y0) to (x1, y1) as the one wall of `contacts`.
std::vector<DemWall> OneSegment(double x0, double y0, double x1, double y1,
                                DemContactForces* contacts) {
  DemWallExtent extent;
  Result<DemWall> wall = MakeSegmentWall(x0, y0, x1, y1, &extent);
  EXPECT_TRUE(wall.ok()) << wall.status().message();
  EXPECT_TRUE(contacts->SetWallExtents({extent}).ok());
  return {*wall};
}

TEST(DemSegmentWall, NormalIsOnTheLeftOfTheDirectionOfTravel) {
  DemWallExtent extent;
  Result<DemWall> wall = MakeSegmentWall(1.0, 2.0, 1.0, 5.0, &extent);  // travelling +y
  ASSERT_TRUE(wall.ok());
  EXPECT_EQ(wall->nx, -1.0);
  EXPECT_EQ(wall->ny, 0.0);
  EXPECT_EQ(extent.lo, 0.0);
  EXPECT_EQ(extent.hi, 3.0);
  EXPECT_FALSE(MakeSegmentWall(1.0, 2.0, 1.0, 2.0, &extent).ok());
  EXPECT_FALSE(MakeSegmentWall(1.0, NAN, 1.0, 2.0, &extent).ok());
}

// Rolling down a 30 degree segment the disk's motion normal to it is a damped linear oscillator
// about the overlap kn d = m g cos(theta) (the tangential law does not enter it), so once the
// oscillation has decayed (damping ratio 0.7, omega = sqrt(kn / m): e^-40 after 0.5 s) the wall
// carries m g cos(theta) whatever the disk does along the slope.
TEST(DemSegmentWall, DiskOnATiltedSegmentCarriesItsWeightsNormalPart) {
  const double theta = std::numbers::pi / 6.0;
  const double c = std::cos(theta), s = std::sin(theta);
  const double radius = 0.5;
  // Centre 5 m along the slope, one radius off it on the normal side (-sin, cos).
  DemParticles p = MakeDisks({{5.0 * c - radius * s, 5.0 * s + radius * c, radius}}, 1000.0);
  const double weight = p.mass[0] * kG;
  DemContactForces contacts = MakeContacts(Settings(0.05));
  std::vector<DemWall> walls = OneSegment(0.0, 0.0, 20.0 * c, 20.0 * s, &contacts);
  DemStepOptions options;
  options.dt = 1.0e-4;
  options.gravity_y = -kG;
  DemCounters counters;
  ASSERT_TRUE(ComputeDemForces(&p, walls, &contacts, options, &counters).ok());
  for (int step = 0; step < 5000; ++step) {
    ASSERT_TRUE(DemStep(&p, &walls, &contacts, options, &counters).ok());
  }
  ASSERT_EQ(contacts.wall_loads()[0].contact_count, 1);
  EXPECT_NEAR(contacts.wall_loads()[0].normal_force, weight * c, 1e-6 * weight * c);
  // Still on the segment, having moved down the slope (it rolls: it is not a line's test).
  const double along = p.x[0] * c + p.y[0] * s;
  EXPECT_LT(along, 5.0);
  EXPECT_GT(along, 0.0);
}

// A disk whose path clears the end (1, 0) by 0.1 m falls in free fall (velocity Verlet is exact
// for constant acceleration) though listed as a wall candidate all the way; the same disk over
// the segment lands on it. A line wall would have caught both.
TEST(DemSegmentWall, DiskBeyondTheEndFallsPastIt) {
  for (const double x : {1.6, 0.9}) {
    DemParticles p = MakeDisks({{x, 0.6, 0.5}}, 1000.0);
    DemContactForces contacts = MakeContacts(Settings(0.5));
    std::vector<DemWall> walls = OneSegment(0.0, 0.0, 1.0, 0.0, &contacts);
    DemStepOptions options;
    options.dt = 1.0e-4;
    options.gravity_y = -kG;
    DemCounters counters;
    ASSERT_TRUE(ComputeDemForces(&p, walls, &contacts, options, &counters).ok());
    int touching_steps = 0;
    const int steps = 5000;
    for (int step = 0; step < steps; ++step) {
      ASSERT_TRUE(DemStep(&p, &walls, &contacts, options, &counters).ok());
      if (contacts.wall_loads()[0].contact_count > 0) ++touching_steps;
    }
    if (x > 1.0) {
      const double t = steps * options.dt;
      EXPECT_EQ(touching_steps, 0);
      EXPECT_GT(counters.wall_checks, 0u);
      EXPECT_EQ(p.x[0], x);
      EXPECT_NEAR(p.y[0], 0.6 - 0.5 * kG * t * t, 1e-9);
    } else {
      EXPECT_GT(touching_steps, 0);
      EXPECT_NEAR(p.y[0], 0.5, 1e-2);  // resting on the segment, overlap m g / kn
    }
  }
}

// One force pass at rest (no damping, no shear history): beyond the end (1, 0) at (1.3, 0.3) the
// disk is pushed along (1, 1)/sqrt(2) by kn (R - 0.3 sqrt(2)); behind the segment at (0.4, -0.3)
// it is pushed down by kn (R - 0.3). The wall's load is the part along its normal (0, 1).
TEST(DemSegmentWall, EndsTouchLikeAPointAndTheBackFaceLikeTheFront) {
  const double r = 0.5;
  DemParticles p = MakeDisks({{1.3, 0.3, r}, {0.4, -0.3, r}}, 1000.0);
  DemContactForces contacts = MakeContacts(Settings(0.05));
  std::vector<DemWall> walls = OneSegment(0.0, 0.0, 1.0, 0.0, &contacts);
  DemCounters counters;
  ASSERT_TRUE(contacts.SetForces(&p, walls, 1e-4, &counters).ok());
  const double end_force = kKn * (r - 0.3 * std::sqrt(2.0));
  EXPECT_NEAR(p.fx[0], end_force / std::sqrt(2.0), 1e-9 * end_force);
  EXPECT_NEAR(p.fy[0], end_force / std::sqrt(2.0), 1e-9 * end_force);
  const double back_force = kKn * (r - 0.3);
  EXPECT_NEAR(p.fx[1], 0.0, 1e-9 * back_force);
  EXPECT_NEAR(p.fy[1], -back_force, 1e-9 * back_force);
  EXPECT_EQ(contacts.wall_loads()[0].contact_count, 2);
  EXPECT_NEAR(contacts.wall_loads()[0].normal_force, end_force / std::sqrt(2.0) - back_force,
              1e-9 * back_force);
}

// A servo lid that is a segment of length 2 over a stack of three disks on a line floor (no
// gravity) holds its target stress on that length: the lid and the floor both carry
// target x length = 1000 N/m at rest.
TEST(DemSegmentWall, ServoSegmentHoldsItsStressOnItsLength) {
  DemParticles p = MakeDisks({{0.0, 0.5, 0.5}, {0.0, 1.5, 0.5}, {0.0, 2.5, 0.5}}, 1.0);
  DemContactSettings settings = Settings(0.05);
  settings.law.kn = 1.0e5;
  settings.law.kt = 2.0e4;
  DemContactForces contacts = MakeContacts(settings);
  DemWallExtent lid_extent;
  Result<DemWall> lid = MakeSegmentWall(1.0, 3.02, -1.0, 3.02, &lid_extent);  // normal down
  ASSERT_TRUE(lid.ok());
  std::vector<DemWall> walls{*MakeWall(0.0, 0.0, 0.0, 1.0), *lid};
  ASSERT_TRUE(contacts.SetWallExtents({DemWallExtent{}, lid_extent}).ok());
  ServoWallSettings servo;
  servo.target_stress = 500.0;
  servo.length = lid_extent.hi - lid_extent.lo;
  servo.gain_fraction = 0.3;
  servo.max_speed = 1.0;
  DemCounters counters;
  RunWithServo(&p, &walls, &contacts, servo, 1, 1.0e-5, 60000, &counters);
  ASSERT_FALSE(HasFatalFailure());
  EXPECT_EQ(servo.length, 2.0);
  EXPECT_NEAR(contacts.wall_loads()[1].normal_force, 1000.0, 1e-4 * 1000.0);
  EXPECT_NEAR(contacts.wall_loads()[0].normal_force, 1000.0, 1e-4 * 1000.0);
  EXPECT_EQ(contacts.wall_loads()[1].contact_count, 1);
}

TEST(DemSegmentWall, BadExtentsAreNamed) {
  DemContactForces contacts = MakeContacts(Settings(0.05));
  const Status reversed = contacts.SetWallExtents({DemWallExtent{}, DemWallExtent{2.0, 1.0}});
  EXPECT_EQ(reversed.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(reversed.message().find("dem.wall_extents[1]"), std::string::npos)
      << reversed.message();
  const Status half_open = contacts.SetWallExtents({DemWallExtent{0.0, INFINITY}});
  EXPECT_NE(half_open.message().find("dem.wall_extents[0]"), std::string::npos);
  EXPECT_TRUE(contacts.SetWallExtents({DemWallExtent{}, DemWallExtent{0.0, 1.0}}).ok());
  EXPECT_TRUE(contacts.wall_extents()[1].finite());
}

}  // namespace
}  // namespace seep::core
