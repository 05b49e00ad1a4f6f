// Determinism: disks falling onto a floor in a periodic box, with friction, some bonds that break,
// and local damping, give bit-identical state after N steps on 1 and 2 OpenMP threads (forces are
// computed per pair and gathered per particle in a fixed order). A few hundred disks stay below
// the pair count at which the pair pass goes to a team; a few thousand compare the one-thread
// pass (each pair adds to its particles' sums) with the team's (slots, then a gather).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "dem_test_util.h"

namespace seep::core {
namespace {

using dem_test::MakeContacts;

struct Snapshot {
  std::vector<double> x, y, vx, vy, omega, fx, fy, torque;
  std::vector<DemContactRecord> contacts;
  std::size_t broken = 0;
  std::size_t pairs = 0;
  DemCounters counters;
};

// `spacing` scales the grid: below 1 the disks start touching (more pairs from the first step).
Snapshot RunScene(int threads, int steps, int cols = 24, int rows = 14, double spacing = 1.0) {
  omp_set_num_threads(threads);
  // cols x rows disks on a loose hex-like grid, radii and positions perturbed by a fixed LCG.
  Packing packing;
  std::uint64_t state = 12345;
  auto next = [&state] {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * (1.0 / 9007199254740992.0);
  };
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const double r = 0.4 + 0.1 * next();
      const double x = 0.5 + spacing * (col + (row % 2) * 0.5) + 0.05 * (next() - 0.5);
      const double y = 0.6 + spacing * row * 0.9 + 0.05 * (next() - 0.5);
      packing.Add(x, y, r);
    }
  }
  Result<DemParticles> made = MakeDemParticles(packing, 1.0);
  EXPECT_TRUE(made.ok());
  DemParticles p = std::move(made).value();
  DemContactSettings settings;
  settings.law.kn = 1.0e5;
  settings.law.kt = 2.0 / 7.0 * 1.0e5;
  settings.law.friction = 0.5;
  settings.law.gamma_n = 50.0;
  settings.skin = 0.05;
  settings.periodic_x = true;
  settings.x0 = 0.0;
  settings.lx = spacing * cols;
  DemContactForces contacts = MakeContacts(settings);
  BondParams bond;
  bond.normal_stiffness = 1.0e5;
  bond.shear_stiffness = 5.0e4;
  bond.tensile_strength = 20.0;
  bond.shear_strength = 20.0;
  Result<std::size_t> bonds = contacts.BondTouchingPairs(&p, bond, 0.02, nullptr);
  EXPECT_TRUE(bonds.ok());
  EXPECT_GT(*bonds, 20u);
  std::vector<DemWall> walls{*MakeWall(0.0, 0.0, 0.0, 1.0)};
  DemStepOptions options;
  options.dt = 2e-4;
  options.gravity_y = -10.0;
  options.local_damping = 0.1;
  Snapshot snap;
  EXPECT_TRUE(ComputeDemForces(&p, walls, &contacts, options, &snap.counters).ok());
  for (int s = 0; s < steps; ++s) {
    EXPECT_TRUE(DemStep(&p, &walls, &contacts, options, &snap.counters).ok());
    snap.broken += contacts.broken_bonds().size();
  }
  snap.x = p.x;
  snap.y = p.y;
  snap.vx = p.vx;
  snap.vy = p.vy;
  snap.omega = p.omega;
  snap.fx = p.fx;
  snap.fy = p.fy;
  snap.torque = p.torque;
  snap.pairs = contacts.pair_count();
  contacts.CollectContacts(&snap.contacts);
  return snap;
}

void ExpectSameBits(const Snapshot& one, const Snapshot& two) {
  EXPECT_TRUE(dem_test::SameBits(one.x, two.x));
  EXPECT_TRUE(dem_test::SameBits(one.y, two.y));
  EXPECT_TRUE(dem_test::SameBits(one.vx, two.vx));
  EXPECT_TRUE(dem_test::SameBits(one.vy, two.vy));
  EXPECT_TRUE(dem_test::SameBits(one.omega, two.omega));
  EXPECT_TRUE(dem_test::SameBits(one.fx, two.fx));
  EXPECT_TRUE(dem_test::SameBits(one.fy, two.fy));
  EXPECT_TRUE(dem_test::SameBits(one.torque, two.torque));
  ASSERT_EQ(one.contacts.size(), two.contacts.size());
  for (std::size_t c = 0; c < one.contacts.size(); ++c) {
    EXPECT_EQ(one.contacts[c].i, two.contacts[c].i);
    EXPECT_EQ(one.contacts[c].j, two.contacts[c].j);
    EXPECT_EQ(std::memcmp(&one.contacts[c].normal_force, &two.contacts[c].normal_force, 8), 0);
    EXPECT_EQ(std::memcmp(&one.contacts[c].shear_force, &two.contacts[c].shear_force, 8), 0);
  }
  EXPECT_EQ(one.broken, two.broken);
  EXPECT_EQ(one.counters.pair_evaluations, two.counters.pair_evaluations);
}

TEST(DemThreads, OneAndTwoThreadsAreBitIdentical) {
  const int steps = 3000;
  const Snapshot one = RunScene(1, steps);
  const Snapshot two = RunScene(2, steps);
  omp_set_num_threads(1);
  // The run exercised what it is meant to: rebuilds, contacts, bond breaks.
  EXPECT_GT(one.counters.neighbour_rebuilds, 3u);
  EXPECT_GT(one.contacts.size(), 200u);
  EXPECT_GT(one.broken, 0u);
  ExpectSameBits(one, two);
}

TEST(DemThreads, OneThreadSumsAndTheTeamsGatherAreBitIdentical) {
  const int steps = 600;
  const Snapshot one = RunScene(1, steps, 100, 40, 0.85);
  const Snapshot two = RunScene(2, steps, 100, 40, 0.85);
  omp_set_num_threads(1);
  EXPECT_GT(one.pairs, 8192u) << "below the team's pair count: both runs take one path";
  EXPECT_GT(one.counters.neighbour_rebuilds, 1u);
  EXPECT_GT(one.broken, 0u);
  for (std::size_t i = 0; i < one.x.size(); ++i) {
    ASSERT_TRUE(std::isfinite(one.x[i]) && std::isfinite(one.y[i])) << "disk " << i;
  }
  ExpectSameBits(one, two);
}

}  // namespace
}  // namespace seep::core
