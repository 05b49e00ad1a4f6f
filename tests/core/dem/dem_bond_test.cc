// Parallel bonds: a bond pulled apart breaks when its tensile force reaches sigma_c A (A = 2 Rb
// in 2D), within one step's force increment, holds below it, and reports the break once.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dem_test_util.h"

namespace seep::core {
namespace {

using dem_test::MakeContacts;
using dem_test::MakeDisks;

struct BondedPair {
  DemParticles particles;
  DemContactForces contacts;
  BondParams bond;
};

BondedPair MakeBondedPair() {
  DemParticles p = MakeDisks({{0.0, 0.0, 0.5}, {1.0, 0.0, 0.5}}, 1.0);
  p.fixed[0] = 1;  // both velocities prescribed: the bond force is a pure function of the motion
  p.fixed[1] = 1;
  DemContactSettings settings;
  settings.law.kn = 1.0e5;
  settings.law.kt = 2.0e4;
  settings.law.friction = 0.5;
  settings.skin = 0.1;
  BondParams bond;
  bond.normal_stiffness = 1.0e6;
  bond.shear_stiffness = 1.0e6;
  bond.radius_multiplier = 1.0;
  bond.tensile_strength = 100.0;
  bond.shear_strength = 1.0e9;
  DemContactForces contacts = MakeContacts(settings);
  Result<std::size_t> made = contacts.BondTouchingPairs(&p, bond, 1e-9, nullptr);
  EXPECT_TRUE(made.ok()) << made.status().ToString();
  EXPECT_EQ(*made, 1u);
  return {std::move(p), std::move(contacts), bond};
}

TEST(DemBond, BreaksWhenTensionReachesStrengthAndHoldsBelow) {
  BondedPair s = MakeBondedPair();
  std::vector<DemWall> walls;
  DemStepOptions options;
  options.dt = 1e-4;
  DemCounters counters;
  const double area = 2.0 * 0.5;                                 // 2 Rb, Rb = 1 x min(R)
  const double strength_force = s.bond.tensile_strength * area;  // 100
  const double v = 0.01;
  // Tension grows by kn_b A v dt per step (the step's force increment).
  const double increment = s.bond.normal_stiffness * area * v * options.dt;  // = 1
  ASSERT_TRUE(ComputeDemForces(&s.particles, walls, &s.contacts, options, &counters).ok());
  s.particles.vx[1] = v;
  // Pull to 90% of the strength, then hold the pair still for many steps: it must not break.
  const int to_90 = static_cast<int>(0.9 * strength_force / increment);
  for (int k = 0; k < to_90; ++k) {
    ASSERT_TRUE(DemStep(&s.particles, &walls, &s.contacts, options, &counters).ok());
  }
  s.particles.vx[1] = 0.0;
  for (int k = 0; k < 5000; ++k) {
    ASSERT_TRUE(DemStep(&s.particles, &walls, &s.contacts, options, &counters).ok());
    ASSERT_TRUE(s.contacts.broken_bonds().empty()) << "broke while held at 90% at step " << k;
  }
  std::vector<DemContactRecord> records;
  s.contacts.CollectContacts(&records);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_TRUE(records[0].bonded);
  EXPECT_GT(records[0].gap, 0.0);  // the bonded pair has opened: gap > 0 for the aperture law
  const double held = -records[0].normal_force;
  EXPECT_NEAR(held, to_90 * increment, 1e-9 * strength_force);
  // Pull again: it must break at the first step whose tension exceeds sigma_c A.
  s.particles.vx[1] = v;
  double tension_before = held;
  bool broke = false;
  for (int k = 0; k < 1000 && !broke; ++k) {
    ASSERT_TRUE(DemStep(&s.particles, &walls, &s.contacts, options, &counters).ok());
    if (!s.contacts.broken_bonds().empty()) {
      broke = true;
      ASSERT_EQ(s.contacts.broken_bonds().size(), 1u);
      EXPECT_EQ(s.contacts.broken_bonds()[0].i, 0);
      EXPECT_EQ(s.contacts.broken_bonds()[0].j, 1);
      EXPECT_EQ(s.contacts.broken_bonds()[0].failure, BondFailure::kTension);
      // The tension it would have reached this step is above the strength, the last one it
      // carried was not: the break is located within one force increment.
      EXPECT_LE(tension_before, strength_force);
      EXPECT_GT(tension_before + increment * (1 + 1e-9), strength_force);
      break;
    }
    s.contacts.CollectContacts(&records);
    ASSERT_EQ(records.size(), 1u);
    tension_before = -records[0].normal_force;
  }
  EXPECT_TRUE(broke);
  EXPECT_EQ(counters.bonds_broken, 1u);
  EXPECT_EQ(s.contacts.intact_bond_count(), 0u);
  // After the break the open pair is no contact and carries no force, and no new event comes.
  ASSERT_TRUE(DemStep(&s.particles, &walls, &s.contacts, options, &counters).ok());
  EXPECT_TRUE(s.contacts.broken_bonds().empty());
  s.contacts.CollectContacts(&records);
  EXPECT_TRUE(records.empty());
  EXPECT_EQ(s.particles.fx[1], 0.0);
}

TEST(DemBond, ShearStrengthBreaksInShear) {
  BondedPair s = MakeBondedPair();
  s.bond.tensile_strength = 1e9;
  s.bond.shear_strength = 50.0;
  ASSERT_TRUE(s.contacts.BondTouchingPairs(&s.particles, s.bond, 1e-9, nullptr).ok());
  std::vector<DemWall> walls;
  DemStepOptions options;
  options.dt = 1e-4;
  DemCounters counters;
  ASSERT_TRUE(ComputeDemForces(&s.particles, walls, &s.contacts, options, &counters).ok());
  // Slide disk 1 along y: relative tangential speed v, shear force grows ks_b A v dt per step
  // (the moment stays zero: no spin), so tau = |Fs| / A reaches tau_c after tau_c/(ks_b v dt).
  const double v = 0.01;
  s.particles.vy[1] = v;
  const double per_step = s.bond.shear_stiffness * v * options.dt;  // stress increment
  const int expected = static_cast<int>(std::floor(s.bond.shear_strength / per_step)) + 1;
  int broke_at = -1;
  for (int k = 1; k <= 2 * expected && broke_at < 0; ++k) {
    ASSERT_TRUE(DemStep(&s.particles, &walls, &s.contacts, options, &counters).ok());
    if (!s.contacts.broken_bonds().empty()) {
      broke_at = k;
      EXPECT_EQ(s.contacts.broken_bonds()[0].failure, BondFailure::kShear);
    }
  }
  // The direction rotates slightly as disk 1 moves (by v t / 1 = 0.05 rad at the break), which
  // shifts the count by a few steps at most.
  EXPECT_NEAR(broke_at, expected, 0.01 * expected);
}

TEST(DemBond, BendingMomentBreaksInTension) {
  BondedPair s = MakeBondedPair();
  s.bond.tensile_strength = 102.0;
  s.bond.shear_strength = 1e9;
  ASSERT_TRUE(s.contacts.BondTouchingPairs(&s.particles, s.bond, 1e-9, nullptr).ok());
  std::vector<DemWall> walls;
  DemStepOptions options;
  options.dt = 1e-4;
  DemCounters counters;
  ASSERT_TRUE(ComputeDemForces(&s.particles, walls, &s.contacts, options, &counters).ok());
  // Disk 1 spins at omega (centres still): M grows by kn_b I omega dt per step and the peripheral
  // stress |M| Rb / I by kn_b Rb omega dt = 1e6 * 0.5 * 0.1 * 1e-4 = 5 per step, so it exceeds
  // sigma_c = 102 at step floor(102 / 5) + 1 = 21 (the normal force stays zero).
  const double omega = 0.1;
  s.particles.omega[1] = omega;
  const double per_step = s.bond.normal_stiffness * 0.5 * omega * options.dt;
  const int expected = static_cast<int>(std::floor(s.bond.tensile_strength / per_step)) + 1;
  int broke_at = -1;
  for (int k = 1; k <= 2 * expected && broke_at < 0; ++k) {
    ASSERT_TRUE(DemStep(&s.particles, &walls, &s.contacts, options, &counters).ok());
    if (!s.contacts.broken_bonds().empty()) {
      broke_at = k;
      EXPECT_EQ(s.contacts.broken_bonds()[0].failure, BondFailure::kTension);
    }
  }
  EXPECT_EQ(broke_at, expected);
}

}  // namespace
}  // namespace seep::core
