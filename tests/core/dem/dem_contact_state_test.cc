// Checkpoint state of DemContactForces: a run saved after N steps and restored into a fresh
// object continues bit-identically to the uninterrupted run (through neighbour-list rebuilds, bond
// breaks, a servo wall and periodic wrapping); bad states are rejected with DataLoss naming the
// field and leave the object unchanged; CollectFlowContacts lists exactly the near and bonded
// pairs of a lattice with known gaps; FindPairs indices read each contact's force and gap from
// the pair table while its version holds.
#include "seep/core/dem/dem_contact_state.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <tuple>
#include <vector>

#include "dem_test_util.h"
#include "seep/core/dem/servo_wall.h"

namespace seep::core {
namespace {

using dem_test::MakeContacts;

using dem_test::SameBits;

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// A bonded hex lattice (rows x cols disks of radius 0.5, touching) on a floor, under gravity, with
// a servo lid pressing down hard enough to break bonds and spread the lattice.
struct Assembly {
  DemContactSettings settings;
  DemParticles particles;
  std::vector<DemWall> walls;  // 0 floor, 1 lid (servo)
  DemContactForces contacts;
  ServoWallSettings servo;
  DemStepOptions options;
};

// Small enough (about 170 pairs) that the pair loop takes the serial path: fast on a loaded
// machine.
constexpr int kRows = 6;
constexpr int kCols = 10;

DemContactSettings AssemblySettings(bool periodic) {
  DemContactSettings s;
  s.law.kn = 1.0e5;
  s.law.kt = 2.0e4;
  s.law.friction = 0.5;
  s.law.gamma_n = 20.0;
  s.skin = 0.02;
  s.periodic_x = periodic;
  s.x0 = 0.0;
  s.lx = kCols;  // the hex rows close on themselves with pitch 1
  return s;
}

Assembly MakeAssembly(bool periodic) {
  DemContactSettings settings = AssemblySettings(periodic);
  Packing packing;
  // Periodic: shifted so that the drift below carries disks across x = lx during the run.
  const double x_offset = periodic ? 0.3 : 0.0;
  const double row_pitch = std::sqrt(3.0) / 2.0;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      packing.Add(x_offset + 0.5 + c + 0.5 * (r % 2), 0.5 + r * row_pitch, 0.5);
    }
  }
  Result<DemParticles> made = MakeDemParticles(packing, 1.0);
  EXPECT_TRUE(made.ok()) << made.status().ToString();
  DemParticles p = std::move(made).value();
  const double top = 0.5 + (kRows - 1) * row_pitch + 0.5 + 0.005;
  std::vector<DemWall> walls{*MakeWall(0.0, 0.0, 0.0, 1.0), *MakeWall(0.0, top, 0.0, -1.0)};
  if (periodic) {
    // A shear cell: the floor slides along x and drags the disks across x = lx, so the rebuilds
    // wrap them.
    walls[0].vx = 3.0;
    std::fill(p.vx.begin(), p.vx.end(), 3.0);
  }
  DemContactForces contacts = MakeContacts(settings);
  BondParams bond;
  bond.normal_stiffness = 1.0e5;
  bond.shear_stiffness = 5.0e4;
  bond.tensile_strength = 40.0;
  bond.shear_strength = 40.0;
  Result<std::size_t> bonds = contacts.BondTouchingPairs(&p, bond, 1e-6, nullptr);
  EXPECT_TRUE(bonds.ok()) << bonds.status().ToString();
  // Every inner disk of a hex lattice has 6 touching neighbours: 3 per disk minus the borders.
  EXPECT_GT(*bonds, static_cast<std::size_t>(2 * kRows * kCols));
  ServoWallSettings servo;
  servo.target_stress = 1000.0;
  servo.length = kCols;
  servo.gain_fraction = 0.3;
  servo.max_speed = 0.5;
  DemStepOptions options;
  options.dt = 1.0e-4;
  options.gravity_y = -10.0;
  options.local_damping = 0.05;
  return Assembly{settings, std::move(p), std::move(walls), std::move(contacts), servo, options};
}

// The step loop of the tests: the servo reads the last pass's lid load, then one DEM step.
void Advance(Assembly* a, int steps, DemCounters* counters, std::size_t* wraps = nullptr) {
  std::vector<double> x_before;
  for (int s = 0; s < steps; ++s) {
    ApplyServo(a->servo, a->contacts.wall_loads()[1], a->options.dt, &a->walls[1], counters);
    if (wraps != nullptr) x_before = a->particles.x;
    ASSERT_TRUE(DemStep(&a->particles, &a->walls, &a->contacts, a->options, counters).ok());
    if (wraps != nullptr) {
      for (std::size_t i = 0; i < x_before.size(); ++i) {
        if (std::abs(a->particles.x[i] - x_before[i]) > 0.5 * a->settings.lx) ++*wraps;
      }
    }
  }
}

// A second assembly with the same settings whose particles, walls and contact state are the
// saved ones: what a resumed job holds.
Assembly RestoredCopy(const Assembly& a, const DemContactState& state) {
  Assembly b{a.settings, a.particles, a.walls, MakeContacts(a.settings), a.servo, a.options};
  const Status st = b.contacts.RestoreState(state, b.particles.size(), b.walls.size());
  EXPECT_TRUE(st.ok()) << st.ToString();
  return b;
}

void ExpectSameParticles(const DemParticles& a, const DemParticles& b) {
  EXPECT_TRUE(SameBits(a.x, b.x));
  EXPECT_TRUE(SameBits(a.y, b.y));
  EXPECT_TRUE(SameBits(a.vx, b.vx));
  EXPECT_TRUE(SameBits(a.vy, b.vy));
  EXPECT_TRUE(SameBits(a.omega, b.omega));
  EXPECT_TRUE(SameBits(a.fx, b.fx));
  EXPECT_TRUE(SameBits(a.fy, b.fy));
  EXPECT_TRUE(SameBits(a.torque, b.torque));
}

void ExpectSameContacts(const DemContactForces& a, const DemContactForces& b) {
  std::vector<DemContactRecord> ra, rb;
  a.CollectContacts(&ra);
  b.CollectContacts(&rb);
  ASSERT_EQ(ra.size(), rb.size());
  for (std::size_t c = 0; c < ra.size(); ++c) {
    EXPECT_EQ(ra[c].i, rb[c].i);
    EXPECT_EQ(ra[c].j, rb[c].j);
    EXPECT_EQ(ra[c].bonded, rb[c].bonded);
    EXPECT_TRUE(SameBits(ra[c].normal_force, rb[c].normal_force)) << c;
    EXPECT_TRUE(SameBits(ra[c].gap, rb[c].gap)) << c;
    EXPECT_TRUE(SameBits(ra[c].shear_force, rb[c].shear_force)) << c;
  }
  std::vector<DemWallContactRecord> wa, wb;
  a.CollectWallContacts(&wa);
  b.CollectWallContacts(&wb);
  ASSERT_EQ(wa.size(), wb.size());
  for (std::size_t c = 0; c < wa.size(); ++c) {
    EXPECT_EQ(wa[c].particle, wb[c].particle);
    EXPECT_EQ(wa[c].wall, wb[c].wall);
    EXPECT_TRUE(SameBits(wa[c].normal_force, wb[c].normal_force)) << c;
    EXPECT_TRUE(SameBits(wa[c].gap, wb[c].gap)) << c;
    EXPECT_TRUE(SameBits(wa[c].shear_force, wb[c].shear_force)) << c;
  }
  ContactList fa, fb;
  a.CollectFlowContacts(a.settings().skin, &fa);
  b.CollectFlowContacts(b.settings().skin, &fb);
  EXPECT_EQ(fa.i, fb.i);
  EXPECT_EQ(fa.j, fb.j);
  EXPECT_TRUE(SameBits(fa.gap, fb.gap));
}

// Every field of two states, bit for bit.
void ExpectSameState(const DemContactState& a, const DemContactState& b) {
  EXPECT_EQ(a.needs_rebuild, b.needs_rebuild);
  EXPECT_TRUE(SameBits(a.bond_normal_stiffness, b.bond_normal_stiffness));
  EXPECT_TRUE(SameBits(a.bond_shear_stiffness, b.bond_shear_stiffness));
  EXPECT_TRUE(SameBits(a.bond_radius_multiplier, b.bond_radius_multiplier));
  EXPECT_TRUE(SameBits(a.bond_tensile_strength, b.bond_tensile_strength));
  EXPECT_TRUE(SameBits(a.bond_shear_strength, b.bond_shear_strength));
  EXPECT_EQ(a.pair_i, b.pair_i);
  EXPECT_EQ(a.pair_j, b.pair_j);
  EXPECT_EQ(a.pair_bond, b.pair_bond);
  EXPECT_TRUE(SameBits(a.pair_damping, b.pair_damping));
  EXPECT_TRUE(SameBits(a.pair_shear, b.pair_shear));
  EXPECT_TRUE(SameBits(a.pair_fn, b.pair_fn));
  EXPECT_TRUE(SameBits(a.pair_gap, b.pair_gap));
  EXPECT_EQ(a.bond_i, b.bond_i);
  EXPECT_EQ(a.bond_j, b.bond_j);
  EXPECT_TRUE(SameBits(a.bond_half_width, b.bond_half_width));
  EXPECT_TRUE(SameBits(a.bond_fn, b.bond_fn));
  EXPECT_TRUE(SameBits(a.bond_fs, b.bond_fs));
  EXPECT_TRUE(SameBits(a.bond_moment, b.bond_moment));
  EXPECT_EQ(a.bond_failure, b.bond_failure);
  EXPECT_EQ(a.bond_reported, b.bond_reported);
  EXPECT_EQ(a.wall_contact_particle, b.wall_contact_particle);
  EXPECT_EQ(a.wall_contact_wall, b.wall_contact_wall);
  EXPECT_TRUE(SameBits(a.wall_contact_shear, b.wall_contact_shear));
  EXPECT_TRUE(SameBits(a.wall_contact_fn, b.wall_contact_fn));
  EXPECT_TRUE(SameBits(a.wall_contact_gap, b.wall_contact_gap));
  EXPECT_TRUE(SameBits(a.wall_load_normal_force, b.wall_load_normal_force));
  EXPECT_TRUE(SameBits(a.wall_load_stiffness_sum, b.wall_load_stiffness_sum));
  EXPECT_TRUE(SameBits(a.wall_load_damping_sum, b.wall_load_damping_sum));
  EXPECT_EQ(a.wall_load_contact_count, b.wall_load_contact_count);
  EXPECT_TRUE(SameBits(a.ref_x, b.ref_x));
  EXPECT_TRUE(SameBits(a.ref_y, b.ref_y));
  EXPECT_TRUE(SameBits(a.ref_wall_x, b.ref_wall_x));
  EXPECT_TRUE(SameBits(a.ref_wall_y, b.ref_wall_y));
}

// Runs `first` steps, saves, restores into a fresh copy, runs both `second` more steps and
// compares everything. Returns the counters of the uninterrupted run's second part.
DemCounters CheckResumeIsBitIdentical(bool periodic, int first, int second,
                                      std::size_t* wraps_in_second) {
  Assembly a = MakeAssembly(periodic);
  DemCounters counters_a;
  EXPECT_TRUE(ComputeDemForces(&a.particles, a.walls, &a.contacts, a.options, &counters_a).ok());
  // Save in the middle of the bond-breaking cascade: `first` steps after the first break.
  for (int s = 0; s < 20000 && counters_a.bonds_broken == 0; ++s) Advance(&a, 1, &counters_a);
  EXPECT_GT(counters_a.bonds_broken, 0u);
  Advance(&a, first, &counters_a);

  const DemContactState saved = a.contacts.SaveState();
  Assembly b = RestoredCopy(a, saved);
  ExpectSameState(saved, b.contacts.SaveState());  // Save(Restore(s)) == s
  // The comparison can fail: a copy restored without the shear histories drifts away.
  DemContactState no_history = saved;
  std::fill(no_history.pair_shear.begin(), no_history.pair_shear.end(), 0.0);
  std::fill(no_history.wall_contact_shear.begin(), no_history.wall_contact_shear.end(), 0.0);
  Assembly c = RestoredCopy(a, no_history);

  DemCounters second_a, second_b, second_c;
  Advance(&a, second, &second_a, wraps_in_second);
  Advance(&b, second, &second_b);
  Advance(&c, second, &second_c);

  ExpectSameParticles(a.particles, b.particles);
  for (std::size_t w = 0; w < a.walls.size(); ++w) {
    EXPECT_TRUE(SameBits(a.walls[w].px, b.walls[w].px));
    EXPECT_TRUE(SameBits(a.walls[w].py, b.walls[w].py));
    EXPECT_TRUE(SameBits(a.walls[w].vx, b.walls[w].vx));
    EXPECT_TRUE(SameBits(a.walls[w].vy, b.walls[w].vy));
  }
  ExpectSameContacts(a.contacts, b.contacts);
  ExpectSameState(a.contacts.SaveState(), b.contacts.SaveState());
  // Same work, in particular the rebuilds at the same steps (integer counters).
  EXPECT_EQ(second_a.neighbour_rebuilds, second_b.neighbour_rebuilds);
  EXPECT_EQ(second_a.pair_checks, second_b.pair_checks);
  EXPECT_EQ(second_a.pair_evaluations, second_b.pair_evaluations);
  EXPECT_EQ(second_a.bond_evaluations, second_b.bond_evaluations);
  EXPECT_EQ(second_a.bonds_broken, second_b.bonds_broken);
  EXPECT_EQ(second_a.wall_evaluations, second_b.wall_evaluations);
  EXPECT_FALSE(SameBits(a.particles.x, c.particles.x));
  return second_a;
}

TEST(DemContactState, PeriodicResumeIsBitIdenticalThroughWrapping) {
  std::size_t wraps = 0;
  const DemCounters second = CheckResumeIsBitIdentical(true, 20, 2000, &wraps);
  EXPECT_GT(second.neighbour_rebuilds, 0u);
  EXPECT_GT(wraps, 0u);
}

TEST(DemContactState, ResumeIsBitIdenticalThroughRebuildsAndBondBreaks) {
  const DemCounters second = CheckResumeIsBitIdentical(false, 20, 1500, nullptr);
  // The continuation exercised what a checkpoint must carry across.
  EXPECT_GT(second.neighbour_rebuilds, 0u);
  EXPECT_GT(second.bonds_broken, 0u);
  EXPECT_GT(second.wall_evaluations, 0u);
}

TEST(DemContactState, RestoreRejectsBadStatesAndLeavesTheObjectUnchanged) {
  Assembly a = MakeAssembly(false);
  DemCounters counters;
  ASSERT_TRUE(ComputeDemForces(&a.particles, a.walls, &a.contacts, a.options, &counters).ok());
  Advance(&a, 150, &counters);  // before the first bond breaks (about step 200)
  const DemContactState good = a.contacts.SaveState();
  ASSERT_GT(good.pair_i.size(), 10u);
  ASSERT_GT(good.wall_contact_particle.size(), 0u);
  const std::size_t n = a.particles.size(), nw = a.walls.size();

  // The object the bad restores are tried on, in another valid state, and a copy of it.
  Assembly b = MakeAssembly(false);
  ASSERT_TRUE(ComputeDemForces(&b.particles, b.walls, &b.contacts, b.options, &counters).ok());
  Advance(&b, 100, &counters);
  const DemContactState before = b.contacts.SaveState();
  Assembly b_copy = RestoredCopy(b, before);

  // Pairs 3 and 4 swapped with all their fields: only the order is wrong, found at pair 4.
  const std::size_t k = 3;
  DemContactState unsorted = good;
  std::swap(unsorted.pair_i[k], unsorted.pair_i[k + 1]);
  std::swap(unsorted.pair_j[k], unsorted.pair_j[k + 1]);
  std::swap(unsorted.pair_bond[k], unsorted.pair_bond[k + 1]);
  DemContactState nan_shear = good;
  nan_shear.pair_shear[3] = std::nan("");
  DemContactState reversed = good;
  std::swap(reversed.pair_i[0], reversed.pair_j[0]);
  DemContactState short_gap = good;
  short_gap.pair_gap.pop_back();
  DemContactState wrong_bond = good;  // a bonded pair pointing at another bond
  std::size_t bonded = 0;
  while (bonded < good.pair_i.size() && good.pair_bond[bonded] < 0) ++bonded;
  ASSERT_LT(bonded, good.pair_i.size());
  ASSERT_GT(good.bond_i.size(), 1u);
  wrong_bond.pair_bond[bonded] = good.pair_bond[bonded] == 0 ? 1 : 0;
  DemContactState bad_wall = good;
  bad_wall.wall_contact_wall[0] = 2;

  struct Case {
    const char* what;
    const DemContactState* state;
    std::size_t particles, walls;
    std::string message;  // the whole message or its start
  };
  const std::string kk = std::to_string(k + 1);
  const Case cases[] = {
      {"one particle more", &good, n + 1, nw,
       "dem_state.ref_x: length 60, expected 61 (one per particle)"},
      {"one particle less", &good, n - 1, nw, "dem_state.ref_x: length 60, expected 59"},
      {"one wall more", &good, n, nw + 1, "dem_state.ref_wall_x: length 2, expected 3"},
      {"unsorted pairs", &unsorted, n, nw,
       "dem_state.pair_i[" + kk + "]: keys not sorted strictly by (pair_i, pair_j)"},
      {"NaN shear", &nan_shear, n, nw, "dem_state.pair_shear[3]: not finite"},
      {"i > j", &reversed, n, nw, "dem_state.pair_i[0]: "},
      {"short array", &short_gap, n, nw, "dem_state.pair_gap: length "},
      {"bond of other disks", &wrong_bond, n, nw,
       "dem_state.pair_bond[" + std::to_string(bonded) + "]: "},
      {"wall id out of range", &bad_wall, n, nw,
       "dem_state.wall_contact_wall[0]: 2 out of range [0, 2)"},
  };
  for (const Case& c : cases) {
    const Status st = b.contacts.RestoreState(*c.state, c.particles, c.walls);
    EXPECT_EQ(st.code(), StatusCode::kDataLoss) << c.what << ": " << st.ToString();
    EXPECT_EQ(st.message().rfind(c.message, 0), 0u) << c.what << ": " << st.message();
    ExpectSameState(before, b.contacts.SaveState());
  }
  // The good state itself is accepted with the right sizes.
  EXPECT_TRUE(ValidateDemContactState(good, n, nw).ok());

  // Nothing hidden was disturbed either: b still runs exactly as its untouched copy.
  DemCounters ignored;
  Advance(&b, 200, &ignored);
  Advance(&b_copy, 200, &ignored);
  ExpectSameParticles(b.particles, b_copy.particles);
  ExpectSameContacts(b.contacts, b_copy.contacts);
}

// A 4 x 3 square lattice of radius-0.5 disks (id = 4 row + column) whose gaps are set: gx[c]
// between columns c and c + 1, gy[r] between rows r and r + 1. Diagonal gaps are about
// sqrt(2) - 1 > skin, so only the 17 lattice edges are ever in the neighbour list.
constexpr int kLatticeCols = 4, kLatticeRows = 3;
constexpr double kGx[kLatticeCols - 1] = {-0.001, 0.02, 0.04};
constexpr double kGy[kLatticeRows - 1] = {0.01, 0.06};

struct Edge {
  std::int32_t i, j;
  double gap;
};

std::vector<Edge> LatticeEdges() {
  std::vector<Edge> edges;
  for (int r = 0; r < kLatticeRows; ++r) {
    for (int c = 0; c < kLatticeCols; ++c) {
      const std::int32_t id = r * kLatticeCols + c;
      if (c + 1 < kLatticeCols) edges.push_back({id, id + 1, kGx[c]});
      if (r + 1 < kLatticeRows) edges.push_back({id, id + kLatticeCols, kGy[r]});
    }
  }
  std::sort(edges.begin(), edges.end(),
            [](const Edge& a, const Edge& b) { return std::tie(a.i, a.j) < std::tie(b.i, b.j); });
  return edges;
}

DemParticles MakeGapLattice() {
  Packing packing;
  double y = 0.0;
  for (int r = 0; r < kLatticeRows; ++r) {
    double x = 0.0;
    for (int c = 0; c < kLatticeCols; ++c) {
      packing.Add(x, y, 0.5);
      if (c + 1 < kLatticeCols) x += 1.0 + kGx[c];
    }
    if (r + 1 < kLatticeRows) y += 1.0 + kGy[r];
  }
  Result<DemParticles> p = MakeDemParticles(packing, 1.0);
  EXPECT_TRUE(p.ok()) << p.status().ToString();
  return std::move(p).value();
}

// The edges with gap <= max_gap or bonded (bonded: gap <= bond_tolerance), sorted.
std::vector<Edge> ExpectedFlowContacts(double max_gap, double bond_tolerance) {
  std::vector<Edge> out;
  for (const Edge& e : LatticeEdges()) {
    if (e.gap <= max_gap || e.gap <= bond_tolerance) out.push_back(e);
  }
  return out;
}

void ExpectFlowContacts(const DemContactForces& contacts, double max_gap, double bond_tolerance) {
  ContactList list;
  contacts.CollectFlowContacts(max_gap, &list);
  const std::vector<Edge> expected = ExpectedFlowContacts(max_gap, bond_tolerance);
  ASSERT_EQ(list.size(), expected.size()) << "max_gap " << max_gap;
  for (std::size_t c = 0; c < expected.size(); ++c) {
    EXPECT_EQ(list.i[c], expected[c].i) << c;
    EXPECT_EQ(list.j[c], expected[c].j) << c;
    // The gap is |x_j - x_i| - 1 of coordinates built by adding three numbers near 1: exact to
    // a few ulps of 3.
    EXPECT_NEAR(list.gap[c], expected[c].gap, 1e-14) << c;
  }
  // FlowContactsAre, the check without the list: true for exactly this list, false for one pair
  // less, one more, or one other.
  EXPECT_TRUE(contacts.FlowContactsAre(max_gap, list.i, list.j)) << "max_gap " << max_gap;
  std::vector<std::int32_t> i = list.i, j = list.j;
  i.push_back(1000);
  j.push_back(1001);
  EXPECT_FALSE(contacts.FlowContactsAre(max_gap, i, j)) << "one more, max_gap " << max_gap;
  if (list.size() == 0) return;
  i.resize(list.size() - 1);
  j.resize(list.size() - 1);
  EXPECT_FALSE(contacts.FlowContactsAre(max_gap, i, j)) << "one less, max_gap " << max_gap;
  i = list.i;
  j = list.j;
  j.back() += 1;
  EXPECT_FALSE(contacts.FlowContactsAre(max_gap, i, j)) << "one other, max_gap " << max_gap;
}

TEST(DemContactState, FlowContactsAreTheNearAndTheBondedPairs) {
  DemContactSettings settings;
  settings.law.kn = 1.0e5;
  settings.law.kt = 2.0e4;
  settings.law.friction = 0.5;
  settings.skin = 0.1;
  DemStepOptions options;
  options.dt = 1.0e-4;
  std::vector<DemWall> walls;
  constexpr double kNoBonds = -1.0;  // below every gap: no edge counts as bonded

  DemParticles p = MakeGapLattice();
  DemContactForces contacts = MakeContacts(settings);
  ContactList list;
  contacts.CollectFlowContacts(settings.skin, &list);
  EXPECT_EQ(list.size(), 0u);  // no force pass yet, no list
  ASSERT_TRUE(ComputeDemForces(&p, walls, &contacts, options, nullptr).ok());
  EXPECT_EQ(contacts.pair_count(), 17u);
  ExpectFlowContacts(contacts, -0.01, kNoBonds);          // none overlaps by 0.01
  ExpectFlowContacts(contacts, 0.0, kNoBonds);            // the overlapping column pairs only
  ExpectFlowContacts(contacts, 0.03, kNoBonds);           // + the gaps 0.01 and 0.02
  ExpectFlowContacts(contacts, settings.skin, kNoBonds);  // every edge

  // Bonds on the gaps <= 0.015 (the overlaps and the first row gap 0.01): listed at any max_gap.
  DemParticles q = MakeGapLattice();
  DemContactForces bonded = MakeContacts(settings);
  BondParams bond;
  bond.normal_stiffness = 1.0e5;
  bond.shear_stiffness = 5.0e4;
  bond.tensile_strength = 1.0e6;
  bond.shear_strength = 1.0e6;
  Result<std::size_t> made = bonded.BondTouchingPairs(&q, bond, 0.015, nullptr);
  ASSERT_TRUE(made.ok()) << made.status().ToString();
  EXPECT_EQ(*made, 3u + 4u);  // 3 column-0 pairs + 4 row-0 pairs
  ASSERT_TRUE(ComputeDemForces(&q, walls, &bonded, options, nullptr).ok());
  ExpectFlowContacts(bonded, -0.01, 0.015);
  ExpectFlowContacts(bonded, 0.03, 0.015);
  ExpectFlowContacts(bonded, settings.skin, 0.015);
}

// On a team, FlowContactsAre splits the pairs into shares, each of which finds where its flow
// contacts sit in the list; the runs must tile the list in share order. On a bed large enough
// for a team (about 28k pairs), two threads give one thread's answer for the list and for lists
// wrong in one entry at the start, at the end and where the shares meet.
TEST(DemContactState, FlowContactsAreTheSameOnATeam) {
  const Result<Packing> lattice = HexLattice(120, 80, 0.5);
  ASSERT_TRUE(lattice.ok());
  Result<DemParticles> p = MakeDemParticles(*lattice, 1.0);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  DemContactSettings settings;
  settings.law.kn = 1.0e5;
  settings.skin = 0.1;
  DemContactForces contacts = MakeContacts(settings);
  DemStepOptions options;
  options.dt = 1.0e-4;
  ASSERT_TRUE(ComputeDemForces(&*p, {}, &contacts, options, nullptr).ok());
  ASSERT_GE(contacts.pair_count(), 2u * 8192u);  // a team of two, kMinParallelItems each
  const double max_gap = 1e-9;
  ContactList list;
  contacts.CollectFlowContacts(max_gap, &list);
  ASSERT_GT(list.size(), 20000u);
  const int threads = omp_get_max_threads();
  const auto answer = [&](int team, const std::vector<std::int32_t>& i,
                          const std::vector<std::int32_t>& j) {
    omp_set_num_threads(team);
    const bool same = contacts.FlowContactsAre(max_gap, i, j);
    omp_set_num_threads(threads);
    return same;
  };
  struct Case {
    std::string name;
    std::vector<std::int32_t> i, j;
    bool same;
  };
  std::vector<Case> cases;
  cases.push_back({"the list", list.i, list.j, true});
  const std::size_t middle = list.size() / 2;  // where two shares meet, give or take a few
  for (const std::size_t at : {std::size_t{0}, middle - 1, middle, middle + 1, list.size() - 1}) {
    Case less{"without entry " + std::to_string(at), list.i, list.j, false};
    less.i.erase(less.i.begin() + static_cast<std::ptrdiff_t>(at));
    less.j.erase(less.j.begin() + static_cast<std::ptrdiff_t>(at));
    cases.push_back(less);
    Case again{"entry " + std::to_string(at) + " twice", list.i, list.j, false};
    again.i.insert(again.i.begin() + static_cast<std::ptrdiff_t>(at), list.i[at]);
    again.j.insert(again.j.begin() + static_cast<std::ptrdiff_t>(at), list.j[at]);
    cases.push_back(again);
    Case other{"entry " + std::to_string(at) + " another pair", list.i, list.j, false};
    other.j[at] += 1;
    cases.push_back(other);
  }
  Case swapped{"two entries swapped where the shares meet", list.i, list.j, false};
  std::swap(swapped.i[middle], swapped.i[middle + 1]);
  std::swap(swapped.j[middle], swapped.j[middle + 1]);
  cases.push_back(swapped);
  Case halves{"the halves swapped", {}, {}, false};
  halves.i.assign(list.i.begin() + static_cast<std::ptrdiff_t>(middle), list.i.end());
  halves.i.insert(halves.i.end(), list.i.begin(),
                  list.i.begin() + static_cast<std::ptrdiff_t>(middle));
  halves.j.assign(list.j.begin() + static_cast<std::ptrdiff_t>(middle), list.j.end());
  halves.j.insert(halves.j.end(), list.j.begin(),
                  list.j.begin() + static_cast<std::ptrdiff_t>(middle));
  cases.push_back(halves);
  Case more{"one more at the end", list.i, list.j, false};
  more.i.push_back(1000000);
  more.j.push_back(1000001);
  cases.push_back(more);
  for (const Case& c : cases) {
    EXPECT_EQ(answer(1, c.i, c.j), c.same) << c.name << ", one thread";
    EXPECT_EQ(answer(2, c.i, c.j), c.same) << c.name << ", two threads";
  }
}

// Between rebuilds a gap can close by up to one skin (each disk moves up to skin/2): a pair just
// beyond the list's cutoff at the last rebuild can come within max_gap unlisted, unless flow_gap
// widened the cutoff.
TEST(DemContactState, FlowGapKeepsFlowContactsCompleteBetweenRebuilds) {
  DemContactSettings bad;
  bad.law.kn = 1.0e5;
  bad.flow_gap = -1.0;
  const Status st = ValidateDemContactSettings(bad);
  EXPECT_EQ(st.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(st.message().rfind("dem.contact.flow_gap: must be finite and >= 0", 0), 0u)
      << st.message();

  const double max_gap = 0.05;
  for (const double flow_gap : {0.0, max_gap}) {
    DemContactSettings settings;
    settings.law.kn = 1.0e5;
    settings.skin = 0.1;
    settings.flow_gap = flow_gap;
    // Gap 0.14: beyond the skin, within skin + max_gap. Both disks approach at v = 0.1 for 480
    // steps of 1e-3: 0.048 each (< skin/2, no rebuild), the gap closes to 0.044 <= max_gap.
    DemParticles p = dem_test::MakeDisks({{0.0, 0.0, 0.5}, {1.14, 0.0, 0.5}}, 1.0);
    p.fixed[0] = p.fixed[1] = 1;
    p.vx[0] = 0.1;
    p.vx[1] = -0.1;
    DemContactForces contacts = MakeContacts(settings);
    std::vector<DemWall> walls;
    DemStepOptions options;
    options.dt = 1.0e-3;
    DemCounters counters;
    ASSERT_TRUE(ComputeDemForces(&p, walls, &contacts, options, &counters).ok());
    for (int s = 0; s < 480; ++s) {
      ASSERT_TRUE(DemStep(&p, &walls, &contacts, options, &counters).ok());
    }
    EXPECT_EQ(counters.neighbour_rebuilds, 1u);
    EXPECT_NEAR(p.x[1] - p.x[0] - 1.0, 0.044, 1e-12);
    ContactList list;
    contacts.CollectFlowContacts(max_gap, &list);
    if (flow_gap == 0.0) {
      EXPECT_EQ(list.size(), 0u);  // the failure flow_gap exists for: the near pair is missing
    } else {
      ASSERT_EQ(list.size(), 1u);
      EXPECT_EQ(list.i[0], 0);
      EXPECT_EQ(list.j[0], 1);
      EXPECT_NEAR(list.gap[0], 0.044, 1e-12);  // 480 additions of 1e-4: error ~1e-14
    }
  }
}

// The flow coupling keeps, per pipe, the index of its DEM pair (FindPairs) and reads force and
// gap from the pair table at every flow update instead of collecting every contact. On the
// bonded lattice mid-run (overlaps, bonds, compressive and tensile forces), the indices of the
// sorted contact list read back each record's normal force and gap bit for bit; a pair that is
// not listed (two far corners, slotted in sorted order) maps to -1. The indices may be kept only
// while pair_table_version() is unchanged: a force pass without a rebuild keeps the version and
// the indices, ForceRebuild() and the next pass change it, and so does RestoreState.
TEST(DemContactState, PairTableIndicesReadTheContactsForceAndGap) {
  Assembly a = MakeAssembly(false);
  DemCounters counters;
  ASSERT_TRUE(ComputeDemForces(&a.particles, a.walls, &a.contacts, a.options, &counters).ok());
  Advance(&a, 150, &counters);  // loaded by gravity and the lid, no bond broken yet
  std::vector<DemContactRecord> records;
  a.contacts.CollectContacts(&records);
  ASSERT_GT(records.size(), 100u);
  std::size_t compressed = 0, tensile = 0, overlapping = 0;
  for (const DemContactRecord& r : records) {
    compressed += r.normal_force > 0.0;
    tensile += r.normal_force < 0.0;
    overlapping += r.gap < 0.0;
  }
  EXPECT_GT(compressed, 0u);
  EXPECT_GT(tensile, 0u);
  EXPECT_GT(overlapping, 0u);

  const std::int32_t far_i = 0, far_j = static_cast<std::int32_t>(a.particles.size()) - 1;
  std::vector<std::int32_t> qi, qj;
  std::size_t far_at = records.size();
  for (std::size_t c = 0; c < records.size(); ++c) {
    if (far_at == records.size() && std::tie(records[c].i, records[c].j) > std::tie(far_i, far_j)) {
      far_at = qi.size();
      qi.push_back(far_i);
      qj.push_back(far_j);
    }
    qi.push_back(records[c].i);
    qj.push_back(records[c].j);
  }
  ASSERT_LT(far_at, records.size()) << "the unlisted pair sits among the contacts, not last";
  std::vector<std::int32_t> index;
  ASSERT_TRUE(a.contacts.FindPairs(qi, qj, &index).ok());
  ASSERT_EQ(index.size(), records.size() + 1);
  EXPECT_EQ(index[far_at], -1);
  for (std::size_t m = 0, c = 0; m < index.size(); ++m) {
    if (m == far_at) continue;
    const DemContactRecord& r = records[c++];
    ASSERT_GE(index[m], 0) << r.i << "-" << r.j;
    EXPECT_LT(static_cast<std::size_t>(index[m]), a.contacts.pair_count());
    EXPECT_EQ(a.contacts.pair_normal_force(index[m]), r.normal_force) << r.i << "-" << r.j;
    EXPECT_EQ(a.contacts.pair_gap(index[m]), r.gap) << r.i << "-" << r.j;
  }

  // Same positions again: no rebuild, same version, same indices.
  const std::uint64_t version = a.contacts.pair_table_version();
  const std::uint64_t rebuilds = counters.neighbour_rebuilds;
  ASSERT_TRUE(ComputeDemForces(&a.particles, a.walls, &a.contacts, a.options, &counters).ok());
  EXPECT_EQ(counters.neighbour_rebuilds, rebuilds);
  EXPECT_EQ(a.contacts.pair_table_version(), version);
  std::vector<std::int32_t> again;
  ASSERT_TRUE(a.contacts.FindPairs(qi, qj, &again).ok());
  EXPECT_EQ(again, index);

  // A query out of order or with unequal lists is refused and writes nothing.
  std::vector<std::int32_t> untouched{7};
  std::vector<std::int32_t> swapped_i = qi, swapped_j = qj;
  std::swap(swapped_i[0], swapped_i[1]);
  std::swap(swapped_j[0], swapped_j[1]);
  EXPECT_EQ(a.contacts.FindPairs(swapped_i, swapped_j, &untouched).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(a.contacts.FindPairs(qi, std::span(qj).first(qj.size() - 1), &untouched).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(untouched, std::vector<std::int32_t>{7});

  a.contacts.ForceRebuild();
  ASSERT_TRUE(ComputeDemForces(&a.particles, a.walls, &a.contacts, a.options, &counters).ok());
  EXPECT_EQ(counters.neighbour_rebuilds, rebuilds + 1);
  EXPECT_NE(a.contacts.pair_table_version(), version);

  DemContactForces restored = MakeContacts(a.settings);
  const std::uint64_t before_restore = restored.pair_table_version();
  ASSERT_TRUE(
      restored.RestoreState(a.contacts.SaveState(), a.particles.size(), a.walls.size()).ok());
  EXPECT_NE(restored.pair_table_version(), before_restore);
}

}  // namespace
}  // namespace seep::core
