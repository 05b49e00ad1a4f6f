// Stable step estimate, particle builder, periodic contacts across the boundary, sorted contact
// keys, and the work counters of pieces a scene does not use.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "dem_test_util.h"

namespace seep::core {
namespace {

using dem_test::MakeContacts;
using dem_test::MakeDisks;

TEST(DemParticles, MassAndInertiaOfADisk) {
  DemParticles p = MakeDisks({{0.0, 0.0, 0.5}}, 2.0);
  EXPECT_DOUBLE_EQ(p.mass[0], 2.0 * std::numbers::pi * 0.25);
  EXPECT_DOUBLE_EQ(p.inertia[0], 0.5 * p.mass[0] * 0.25);
  EXPECT_FALSE(MakeDemParticles(Packing{}, -1.0).ok());
}

TEST(DemStableStep, KnownMassAndStiffness) {
  DemParticles p = MakeDisks({{0.0, 0.0, 0.5}, {5.0, 0.0, 1.0}}, 1.0);
  const double m = std::numbers::pi * 0.25;  // the lighter disk decides
  // Translation only (kt = 0): dt = safety sqrt(m / kn).
  Result<double> dt = EstimateStableTimeStep(p, 1.0e4, 0.0, 0.5);
  ASSERT_TRUE(dt.ok());
  EXPECT_DOUBLE_EQ(*dt, 0.5 * std::sqrt(m / 1.0e4));
  // With kt = kn the rotational term sqrt(I / (kt R^2)) = sqrt(m / (2 kt)) is smaller.
  dt = EstimateStableTimeStep(p, 1.0e4, 1.0e4, 0.5);
  ASSERT_TRUE(dt.ok());
  EXPECT_DOUBLE_EQ(*dt, 0.5 * std::sqrt(0.5 * m * 0.25 / (1.0e4 * 0.25)));
  EXPECT_FALSE(EstimateStableTimeStep(p, 0.0, 0.0, 0.5).ok());
}

TEST(DemStableStep, ParallelBondsStiffenTranslationAndRotation) {
  // One disk, R = 0.5, rho = 1: m = pi/4, I = m R^2 / 2. A bond of lambda = 1 has A = 2 R = 1.
  DemParticles p = MakeDisks({{0.0, 0.0, 0.5}}, 1.0);
  const double m = std::numbers::pi * 0.25, inertia = 0.5 * m * 0.25;
  BondParams bonds;
  bonds.normal_stiffness = 3.0e4;  // kn_b A = 3e4 beside kn = 1e4
  bonds.shear_stiffness = 0.0;
  bonds.radius_multiplier = 1.0;
  bonds.tensile_strength = bonds.shear_strength = 1.0;
  // kt = 0, ks_b = 0: translation sqrt(m / (kn + kn_b A)) = sqrt(m / 4e4) against the bond's
  // bending sqrt(I / (kn_b A^3 / 12)) = sqrt(I / 2.5e3) = sqrt(m / 2e4): translation decides.
  Result<double> dt = EstimateStableTimeStep(p, 1.0e4, 0.0, 0.5, &bonds);
  ASSERT_TRUE(dt.ok());
  EXPECT_DOUBLE_EQ(*dt, 0.5 * std::sqrt(m / 4.0e4));
  // ks_b A R^2 = 1e5 * 0.25 and kt R^2 = 1e4 * 0.25 join the bending: rotation decides.
  bonds.shear_stiffness = 1.0e5;
  dt = EstimateStableTimeStep(p, 1.0e4, 1.0e4, 0.5, &bonds);
  ASSERT_TRUE(dt.ok());
  EXPECT_DOUBLE_EQ(*dt, 0.5 * std::sqrt(inertia / (1.1e5 * 0.25 + 3.0e4 / 12.0)));
  // Without bonds the same call is the contact's step, twice as long.
  EXPECT_DOUBLE_EQ(*EstimateStableTimeStep(p, 1.0e4, 0.0, 0.5), 0.5 * std::sqrt(m / 1.0e4));
}

TEST(DemContacts, PeriodicPairAcrossTheBoundaryPushesApart) {
  // Disks at x = 0.3 and x = 9.8 in [0, 10): 0.5 apart through the boundary, radii 0.3 each,
  // so they overlap by 0.1 and the force is kn * 0.1 along x, pushing 0 right and 1 left.
  DemParticles p = MakeDisks({{0.3, 0.0, 0.3}, {9.8, 0.0, 0.3}}, 1.0);
  DemContactSettings settings;
  settings.law.kn = 1000.0;
  settings.skin = 0.1;
  settings.periodic_x = true;
  settings.lx = 10.0;
  DemContactForces contacts = MakeContacts(settings);
  DemCounters counters;
  p.ClearForces();
  ASSERT_TRUE(contacts.AddForces(&p, {}, 1e-4, &counters).ok());
  EXPECT_NEAR(p.fx[0], 100.0, 1e-9);
  EXPECT_NEAR(p.fx[1], -100.0, 1e-9);
  std::vector<DemContactRecord> records;
  contacts.CollectContacts(&records);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_NEAR(records[0].gap, -0.1, 1e-12);
  EXPECT_NEAR(records[0].normal_force, 100.0, 1e-9);
}

TEST(DemContacts, ContactsAreSortedAndCountersOfAbsentPiecesStayZero) {
  DemParticles p = MakeDisks({{1.9, 0.5, 0.5}, {0.0, 0.5, 0.5}, {0.95, 0.5, 0.5}}, 1.0);
  DemContactSettings settings;
  settings.law.kn = 1000.0;
  settings.skin = 0.1;
  DemContactForces contacts = MakeContacts(settings);
  std::vector<DemWall> walls;
  DemStepOptions options;  // no gravity, no local damping
  options.dt = 1e-4;
  DemCounters counters;
  ASSERT_TRUE(ComputeDemForces(&p, walls, &contacts, options, &counters).ok());
  ASSERT_TRUE(DemStep(&p, &walls, &contacts, options, &counters).ok());
  std::vector<DemContactRecord> records;
  contacts.CollectContacts(&records);
  ASSERT_EQ(records.size(), 2u);  // (0, 2) and (1, 2), in key order
  EXPECT_EQ(records[0].i, 0);
  EXPECT_EQ(records[0].j, 2);
  EXPECT_EQ(records[1].i, 1);
  EXPECT_EQ(records[1].j, 2);
  EXPECT_EQ(counters.neighbour_rebuilds, 1u);
  EXPECT_EQ(counters.pair_evaluations, 4u);  // 2 contacts x 2 force passes
  EXPECT_EQ(counters.gravity_applications, 0u);
  EXPECT_EQ(counters.local_damping_applications, 0u);
  EXPECT_EQ(counters.bond_evaluations, 0u);
  EXPECT_EQ(counters.wall_checks, 0u);
  EXPECT_EQ(counters.servo_updates, 0u);
}

// PFC local damping takes sign(v) = 0 at rest, and a velocity at rounding level (below
// kRestFraction of what the force gives in a step) is rest: its sign, which rounding decides,
// must not put alpha |F| on the particle one way or the other.
TEST(DemLocalDamping, AVelocityAtRoundingLevelIsRest) {
  DemParticles p = MakeDisks({{0.0, 0.0, 0.5}, {5.0, 0.0, 0.5}}, 1.0);
  const double dt = 1e-3;
  const double step_velocity = 2.0 * dt * p.inv_mass[0];  // what F = 2 gives in a step
  p.fx = {2.0, 2.0};
  p.fy = {0.0, 0.0};
  p.vx = {1e-20 * step_velocity, -1e-20 * step_velocity};  // rounding: either sign, undamped
  p.vy = {0.0, 0.0};
  ApplyLocalDamping(&p, 0.5, dt, nullptr);
  EXPECT_EQ(p.fx[0], 2.0);
  EXPECT_EQ(p.fx[1], 2.0);
  p.fx = {2.0, 2.0};
  p.vx = {1e-6 * step_velocity, -1e-6 * step_velocity};  // moving: damped against the motion
  ApplyLocalDamping(&p, 0.5, dt, nullptr);
  EXPECT_EQ(p.fx[0], 1.0);
  EXPECT_EQ(p.fx[1], 3.0);
}

}  // namespace
}  // namespace seep::core
