// Local re-detection against the full one: after every contact that breaks or forms, the patched
// network must be the very DomainNetwork that DomainDetector gives for the same contacts (every
// id, every bit), and most changes must have been patched locally.
#include "seep/core/geometry/local_domain_detection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/geometry/random_packing.h"

namespace seep::core {
namespace {

// Every field, compared exactly: a local patch must reproduce the full detection's sums bit for
// bit (same first half-edge, same order of terms).
void ExpectSameNetwork(const DomainNetwork& full, const DomainNetwork& local) {
  EXPECT_EQ(full.loop_offsets, local.loop_offsets);
  EXPECT_EQ(full.loop_particles, local.loop_particles);
  EXPECT_EQ(full.loop_contacts, local.loop_contacts);
  EXPECT_EQ(full.apparent_volume, local.apparent_volume);
  EXPECT_EQ(full.pore_volume, local.pore_volume);
  EXPECT_EQ(full.centroid_x, local.centroid_x);
  EXPECT_EQ(full.centroid_y, local.centroid_y);
  EXPECT_EQ(full.is_boundary, local.is_boundary);
  EXPECT_EQ(full.pipe_domain_a, local.pipe_domain_a);
  EXPECT_EQ(full.pipe_domain_b, local.pipe_domain_b);
  EXPECT_EQ(full.pipe_contact, local.pipe_contact);
  EXPECT_EQ(full.pipe_length, local.pipe_length);
  EXPECT_EQ(full.boundary_pipe_domain, local.boundary_pipe_domain);
  EXPECT_EQ(full.boundary_pipe_contact, local.boundary_pipe_contact);
  EXPECT_EQ(full.boundary_pipe_outer_face, local.boundary_pipe_outer_face);
  EXPECT_EQ(full.boundary_pipe_length, local.boundary_pipe_length);
  EXPECT_EQ(full.boundary_pipe_x, local.boundary_pipe_x);
  EXPECT_EQ(full.boundary_pipe_y, local.boundary_pipe_y);
  EXPECT_EQ(full.outer_offsets, local.outer_offsets);
  EXPECT_EQ(full.outer_particles, local.outer_particles);
  EXPECT_EQ(full.outer_contacts, local.outer_contacts);
  EXPECT_EQ(full.outer_area, local.outer_area);
  EXPECT_EQ(full.outer_host_domain, local.outer_host_domain);
  EXPECT_EQ(full.euler.vertices, local.euler.vertices);
  EXPECT_EQ(full.euler.edges, local.euler.edges);
  EXPECT_EQ(full.euler.cycles, local.euler.cycles);
  EXPECT_EQ(full.euler.components, local.euler.components);
  EXPECT_EQ(full.num_pruned_particles, local.num_pruned_particles);
  EXPECT_EQ(full.num_nonpositive_domains, local.num_nonpositive_domains);
  EXPECT_TRUE(full == local);  // and every field not named above (the walls)
}

struct Contact {
  std::int32_t i, j;
  double gap;
};

// Compares the local detector with a full detection of the contacts it holds, and those contacts
// with the ones the test expects.
void ExpectMatchesFullDetection(const Packing& packing, const LocalDomainDetector& local,
                                const std::vector<Contact>& expected_contacts, double max_gap) {
  ContactList held;
  local.EmitContacts(&held);
  std::vector<Contact> sorted = expected_contacts;
  std::sort(sorted.begin(), sorted.end(), [](const Contact& a, const Contact& b) {
    return a.i < b.i || (a.i == b.i && a.j < b.j);
  });
  ASSERT_EQ(held.size(), sorted.size());
  for (std::size_t c = 0; c < sorted.size(); ++c) {
    ASSERT_EQ(held.i[c], sorted[c].i);
    ASSERT_EQ(held.j[c], sorted[c].j);
    ASSERT_EQ(held.gap[c], sorted[c].gap);
  }
  DomainNetwork full;
  DomainDetector detector;
  ASSERT_TRUE(detector.Detect(packing, held, {max_gap}, &full).ok());
  DomainNetwork patched;
  local.Emit(&patched);
  ExpectSameNetwork(full, patched);
}

std::vector<Contact> ToVector(const ContactList& list) {
  std::vector<Contact> out;
  for (std::size_t c = 0; c < list.size(); ++c) out.push_back({list.i[c], list.j[c], list.gap[c]});
  return out;
}

// Random breaks and re-formations on a random packing with rattlers, several components near the
// edges and contacts above max_gap (listed but not edges).
void RunRandomSequence(std::uint64_t seed, int steps, double break_probability,
                       double min_local_share) {
  RandomPackingOptions options;
  options.count = 500;
  options.porosity = 0.2;
  options.seed = seed;
  const Result<RandomPacking> generated = GenerateRandomPacking(options);
  ASSERT_TRUE(generated.ok()) << generated.status().ToString();
  const Packing& packing = generated->packing;
  const double max_gap = 0.01 * generated->mean_radius;
  const Result<ContactList> listed = DetectContacts(packing, 0.05 * generated->mean_radius);
  ASSERT_TRUE(listed.ok());

  LocalDomainDetector local;
  ASSERT_TRUE(local.Reset(packing, *listed, {max_gap}).ok());
  std::vector<Contact> current = ToVector(*listed);
  std::vector<Contact> broken;
  ExpectMatchesFullDetection(packing, local, current, max_gap);
  DomainNetwork start;
  local.Emit(&start);
  ASSERT_GT(start.num_pruned_particles, 0);  // rattlers and trees: their paths are exercised too

  std::mt19937_64 rng(seed);
  int local_updates = 0;
  int graph_changes = 0;
  for (int step = 0; step < steps; ++step) {
    const bool do_break =
        broken.empty() ||
        (!current.empty() && std::uniform_real_distribution<>(0.0, 1.0)(rng) < break_probability);
    if (do_break) {
      const std::size_t k = std::uniform_int_distribution<std::size_t>(0, current.size() - 1)(rng);
      const Contact c = current[k];
      current.erase(current.begin() + static_cast<std::ptrdiff_t>(k));
      broken.push_back(c);
      // Either order of the ids names the contact.
      ASSERT_TRUE((step % 2 ? local.RemoveContact(c.j, c.i) : local.RemoveContact(c.i, c.j)).ok());
    } else {
      const std::size_t k = std::uniform_int_distribution<std::size_t>(0, broken.size() - 1)(rng);
      const Contact c = broken[k];
      broken.erase(broken.begin() + static_cast<std::ptrdiff_t>(k));
      current.push_back(c);
      ASSERT_TRUE(local.AddContact(c.i, c.j, c.gap).ok());
    }
    if (local.last_update() != LocalDomainDetector::Update::kContactListOnly) ++graph_changes;
    if (local.last_update() == LocalDomainDetector::Update::kLocal) ++local_updates;
    ExpectMatchesFullDetection(packing, local, current, max_gap);
    if (testing::Test::HasFailure()) {
      FAIL() << "first mismatch after step " << step << (do_break ? " (break)" : " (form)");
    }
  }
  // Most graph changes are patched locally; a detector that always fell back would fail here.
  EXPECT_GE(local_updates, min_local_share * graph_changes)
      << local_updates << " of " << graph_changes;
  EXPECT_EQ(local.num_local_updates(), local_updates);
}

TEST(LocalDomainDetection, RandomBreakSequencesEqualFullDetection) {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    RunRandomSequence(seed, 150, 1.0, 0.95);  // breaks only: a seventh of the contacts
  }
}

TEST(LocalDomainDetection, RandomBreakAndReformSequencesEqualFullDetection) {
  for (const std::uint64_t seed : {4u, 5u}) {
    SCOPED_TRACE(seed);
    RunRandomSequence(seed, 600, 0.55, 0.95);
  }
}

// A square lattice: a broken interior bond merges two squares into a 4R x 2R rectangle, locally;
// a broken hull bond opens a square into the outside; re-forming both splits them again.
TEST(LocalDomainDetection, LatticeMergesAndSplitsLocallyWithTheirAreas) {
  const double R = 1.0;
  const Packing packing = SquareLattice(5, 5, R).value();
  const double max_gap = 1e-9;
  const ContactList contacts = DetectContacts(packing, max_gap).value();
  LocalDomainDetector local;
  ASSERT_TRUE(local.Reset(packing, contacts, {max_gap}).ok());
  ASSERT_EQ(local.num_domains(), 16u);
  std::vector<Contact> current = ToVector(contacts);

  // Interior bond between particles 12 and 13 (row 2, columns 2 and 3).
  ASSERT_TRUE(local.RemoveContact(12, 13).ok());
  EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kLocal);
  EXPECT_EQ(local.num_domains(), 15u);
  std::erase_if(current, [](const Contact& c) { return c.i == 12 && c.j == 13; });
  ExpectMatchesFullDetection(packing, local, current, max_gap);
  DomainNetwork net;
  local.Emit(&net);
  double largest = 0.0;
  for (double v : net.apparent_volume) largest = std::max(largest, v);
  EXPECT_NEAR(largest, 8.0 * R * R, 1e-12);

  // Hull bond between particles 1 and 2: the square beside it joins the outside.
  ASSERT_TRUE(local.RemoveContact(1, 2).ok());
  EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kLocal);
  EXPECT_EQ(local.num_domains(), 14u);
  std::erase_if(current, [](const Contact& c) { return c.i == 1 && c.j == 2; });
  ExpectMatchesFullDetection(packing, local, current, max_gap);

  // Corner bond 0-1: particle 0 keeps one contact, and so does particle 1 (its bond to 2 is
  // broken): both are pruned as a chain, and the two squares beside them join the outside.
  ASSERT_TRUE(local.RemoveContact(0, 1).ok());
  EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kLocal);
  std::erase_if(current, [](const Contact& c) { return c.i == 0 && c.j == 1; });
  ExpectMatchesFullDetection(packing, local, current, max_gap);
  local.Emit(&net);
  EXPECT_EQ(net.num_pruned_particles, 2);

  // Re-formed, 0-1 closes the chain into a path between live particles 5 and 6 again; 1-2 then
  // splits the outside once more.
  for (const Contact& c : {Contact{0, 1, 0.0}, Contact{1, 2, 0.0}, Contact{12, 13, 0.0}}) {
    ASSERT_TRUE(local.AddContact(c.i, c.j, c.gap).ok());
    EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kLocal);
    current.push_back(c);
    ExpectMatchesFullDetection(packing, local, current, max_gap);
  }
  EXPECT_EQ(local.num_domains(), 16u);
  EXPECT_EQ(local.num_full_updates(), 0);
}

// Two squares joined by a one-particle chain: breaking the chain splits the component, and
// re-forming it joins two components. Neither is a local patch; both fall back to a full
// re-detection, whose network the detector then carries on from.
TEST(LocalDomainDetection, ComponentChangesFallBackToAFullDetection) {
  Packing packing;
  for (const double x0 : {0.0, 6.0}) {
    packing.Add(x0, 0.0, 1.0);
    packing.Add(x0 + 2.0, 0.0, 1.0);
    packing.Add(x0, 2.0, 1.0);
    packing.Add(x0 + 2.0, 2.0, 1.0);
  }
  packing.Add(4.0, 0.0, 1.0);  // particle 8, between particles 1 and 4
  const double max_gap = 1e-9;
  const ContactList contacts = DetectContacts(packing, max_gap).value();
  LocalDomainDetector local;
  ASSERT_TRUE(local.Reset(packing, contacts, {max_gap}).ok());
  ASSERT_EQ(local.num_domains(), 2u);
  std::vector<Contact> current = ToVector(contacts);

  ASSERT_TRUE(local.RemoveContact(1, 8).ok());
  EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kFull);
  std::erase_if(current, [](const Contact& c) { return c.i == 1 && c.j == 8; });
  ExpectMatchesFullDetection(packing, local, current, max_gap);
  DomainNetwork net;
  local.Emit(&net);
  EXPECT_EQ(net.euler.components, 2);
  EXPECT_EQ(net.num_pruned_particles, 1);

  ASSERT_TRUE(local.AddContact(1, 8, 0.0).ok());
  EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kFull);
  current.push_back({1, 8, 0.0});
  ExpectMatchesFullDetection(packing, local, current, max_gap);
  EXPECT_EQ(local.num_full_updates(), 2);

  // Back in one component, an interior change is local again.
  ASSERT_TRUE(local.RemoveContact(0, 1).ok());
  EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kLocal);
  std::erase_if(current, [](const Contact& c) { return c.i == 0 && c.j == 1; });
  ExpectMatchesFullDetection(packing, local, current, max_gap);
}

// An island (a 3 x 2 lattice, two squares) inside a ring of 16 disks: the island's inner bond
// merges and splits its own two domains locally; a change beside the host domain, which holds the
// island, falls back, and so does a broken ring (its whole component is pruned away).
TEST(LocalDomainDetection, IslandsKeepTheirHostAndFallBackAroundIt) {
  Packing packing;
  const double R = 1.0;
  const int ring = 16;
  const double rho = R / std::sin(std::numbers::pi / ring);
  for (int k = 0; k < ring; ++k) {
    const double a = 2.0 * std::numbers::pi * k / ring;
    packing.Add(rho * std::cos(a), rho * std::sin(a), R);
  }
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 3; ++col) packing.Add(2.0 * (col - 1), 2.0 * row - 1.0, R);
  }
  const double max_gap = 1e-9;
  const ContactList contacts = DetectContacts(packing, max_gap).value();
  LocalDomainDetector local;
  ASSERT_TRUE(local.Reset(packing, contacts, {max_gap}).ok());
  DomainNetwork net;
  local.Emit(&net);
  ASSERT_EQ(net.euler.components, 2);
  ASSERT_EQ(net.num_domains(), 3u);
  std::vector<Contact> current = ToVector(contacts);

  // The island's middle bond: particles 17 and 20 (column 1 of rows 0 and 1).
  ASSERT_TRUE(local.RemoveContact(17, 20).ok());
  EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kLocal);
  std::erase_if(current, [](const Contact& c) { return c.i == 17 && c.j == 20; });
  ExpectMatchesFullDetection(packing, local, current, max_gap);
  ASSERT_TRUE(local.AddContact(17, 20, 0.0).ok());
  EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kLocal);
  current.push_back({17, 20, 0.0});
  ExpectMatchesFullDetection(packing, local, current, max_gap);

  // A ring bond: the ring is pruned away, the island becomes top level.
  ASSERT_TRUE(local.RemoveContact(0, 1).ok());
  EXPECT_EQ(local.last_update(), LocalDomainDetector::Update::kFull);
  std::erase_if(current, [](const Contact& c) { return c.i == 0 && c.j == 1; });
  ExpectMatchesFullDetection(packing, local, current, max_gap);
  local.Emit(&net);
  EXPECT_EQ(net.num_domains(), 2u);
  EXPECT_EQ(net.num_pruned_particles, ring);
}

TEST(LocalDomainDetection, BadChangesAreRejectedAndChangeNothing) {
  const Packing packing = SquareLattice(3, 3, 1.0).value();
  const ContactList contacts = DetectContacts(packing, 1e-9).value();
  LocalDomainDetector local;
  ASSERT_TRUE(local.Reset(packing, contacts, {1e-9}).ok());
  const std::vector<Contact> current = ToVector(contacts);

  const Status missing = local.RemoveContact(0, 4);
  EXPECT_EQ(missing.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(missing.message().find("(0, 4) is not a current contact"), std::string::npos);
  const Status twice = local.AddContact(1, 0, 0.0);
  EXPECT_EQ(twice.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(twice.message().find("(0, 1) is already a contact"), std::string::npos);
  EXPECT_EQ(local.AddContact(0, 9, 0.0).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(local.AddContact(3, 3, 0.0).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(local.AddContact(0, 4, std::nan("")).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(local.RemoveContact(-1, 2).code(), StatusCode::kInvalidArgument);
  ExpectMatchesFullDetection(packing, local, current, 1e-9);
}

}  // namespace
}  // namespace seep::core
