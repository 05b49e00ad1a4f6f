// A cascade of bond breaks that merges many domains in one re-detection (docs/physics.md §2.6, V16
// generalised): RemapPressures must conserve the stored fluid sum V_s P and the storage sum V_s
// to rounding, and give every new domain a pressure inside the range of the old ones it covers
// (a volume-weighted mean cannot leave it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/network/pressure_remap.h"
#include "stability_invariants.h"

namespace seep::core {
namespace {

constexpr double kRadius = 1e-3;

ContactList Keep(const ContactList& contacts, const std::vector<std::uint8_t>& removed) {
  ContactList out;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (removed[c]) continue;
    out.i.push_back(contacts.i[c]);
    out.j.push_back(contacts.j[c]);
    out.gap.push_back(contacts.gap[c]);
  }
  return out;
}

DomainNetwork Detect(const Packing& packing, const ContactList& contacts) {
  auto d = DetectDomains(packing, contacts);
  EXPECT_TRUE(d.ok()) << d.status().ToString();
  return d.ok() ? std::move(*d) : DomainNetwork{};
}

struct Sums {
  double volume = 0.0;  // sum V_p, m^2
  double stored = 0.0;  // sum V_p P, m^2 Pa
};
Sums SumsOf(const DomainNetwork& d, const std::vector<double>& p) {
  Sums s;
  for (std::size_t k = 0; k < d.num_domains(); ++k) {
    s.volume += d.pore_volume[k];
    s.stored += d.pore_volume[k] * p[k];
  }
  return s;
}

// Breaks about `fraction` of the pipe contacts at once, picked in seeded random order, skipping a
// contact when taking it would leave one of its particles with fewer than two contacts (it would
// be pruned as a dangling end) or one of its domains with none of its own loop contacts (see the
// disabled test below). Returns the contact mask.
std::vector<std::uint8_t> BreakMany(const DomainNetwork& d, const ContactList& contacts,
                                    std::size_t num_particles, double fraction,
                                    std::uint64_t seed) {
  std::vector<int> degree(num_particles, 0);
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    ++degree[contacts.i[c]];
    ++degree[contacts.j[c]];
  }
  std::vector<int> loop_left(d.num_domains());
  for (std::size_t k = 0; k < d.num_domains(); ++k) {
    loop_left[k] = d.loop_offsets[k + 1] - d.loop_offsets[k];
  }
  std::vector<std::size_t> order(d.num_pipes());
  for (std::size_t p = 0; p < order.size(); ++p) order[p] = p;
  std::mt19937_64 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<std::uint8_t> removed(contacts.size(), 0);
  const auto target = static_cast<std::size_t>(fraction * static_cast<double>(d.num_pipes()));
  std::size_t taken = 0;
  for (const std::size_t p : order) {
    if (taken == target) break;
    const auto c = static_cast<std::size_t>(d.pipe_contact[p]);
    const auto a = static_cast<std::size_t>(d.pipe_domain_a[p]);
    const auto b = static_cast<std::size_t>(d.pipe_domain_b[p]);
    if (degree[contacts.i[c]] <= 2 || degree[contacts.j[c]] <= 2) continue;
    if (loop_left[a] <= 1 || loop_left[b] <= 1) continue;
    removed[c] = 1;
    --degree[contacts.i[c]];
    --degree[contacts.j[c]];
    --loop_left[a];
    --loop_left[b];
    ++taken;
  }
  return removed;
}

void CheckCascade(const Packing& packing, double fraction, std::uint64_t seed, int rounds) {
  ContactList contacts;
  ContactDetector detector;
  ASSERT_TRUE(detector.Detect(packing, 1e-12, &contacts).ok());
  DomainNetwork before = Detect(packing, contacts);
  std::vector<double> p(before.num_domains());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (double& v : p) v = 1e6 * unit(rng);
  const double lo = *std::min_element(p.begin(), p.end());
  const double hi = *std::max_element(p.begin(), p.end());
  const Sums start = SumsOf(before, p);
  double worst = 0.0;
  for (int round = 0; round < rounds; ++round) {
    SCOPED_TRACE(::testing::Message() << "round " << round);
    const std::vector<std::uint8_t> removed =
        BreakMany(before, contacts, packing.size(), fraction, seed + round);
    contacts = Keep(contacts, removed);
    const DomainNetwork after = Detect(packing, contacts);
    const std::size_t broken =
        static_cast<std::size_t>(std::count(removed.begin(), removed.end(), 1));
    // Each broken pipe contact joins two faces: the first round merges at least a quarter of the
    // domains at once, later rounds whatever the constraints of BreakMany still allow.
    ASSERT_GE(broken, round == 0 ? before.num_domains() / 8 : 1);
    std::printf("[ measured ] round %d: %zu contacts broken at once, %zu -> %zu domains\n", round,
                broken, before.num_domains(), after.num_domains());
    ASSERT_LT(after.num_domains(), before.num_domains());
    std::vector<double> q;
    const auto r = RemapPressures(before, p, after, {}, &q);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->unmatched_old, 0);
    EXPECT_EQ(r->unmatched_new, 0);
    EXPECT_EQ(r->clusters, static_cast<std::int32_t>(after.num_domains()));
    const Sums old_sums = SumsOf(before, p);
    const Sums new_sums = SumsOf(after, q);
    // Sums of ~400 positive terms regrouped: rounding is a few 1e-16; 1e-12 is the bound.
    const double volume_error = std::abs(new_sums.volume - old_sums.volume) / old_sums.volume;
    const double stored_error = std::abs(new_sums.stored - old_sums.stored) / old_sums.stored;
    const double cumulative = std::abs(new_sums.stored - start.stored) / start.stored;
    EXPECT_LE(volume_error, 1e-12);
    EXPECT_LE(stored_error, 1e-12);
    EXPECT_LE(cumulative, 1e-12);
    worst = std::max({worst, volume_error, stored_error, cumulative});
    for (std::size_t k = 0; k < q.size(); ++k) {
      ASSERT_TRUE(std::isfinite(q[k]));
      // A weighted mean of values in [lo, hi], rounded: a few ulps of hi at most.
      ASSERT_GE(q[k], lo - 1e-13 * hi) << "new domain " << k;
      ASSERT_LE(q[k], hi + 1e-13 * hi) << "new domain " << k;
    }
    before = after;
    p = q;
  }
  stability::PrintMeasured("merge cascade worst relative fluid/volume error", worst);
}

TEST(Stability, MergeCascadeOnSquareLatticeConservesFluid) {
  auto packing = SquareLattice(21, 21, kRadius);  // 400 domains
  ASSERT_TRUE(packing.ok());
  CheckCascade(*packing, 0.2, 17, 3);
}

TEST(Stability, MergeCascadeOnHexLatticeConservesFluid) {
  auto packing = HexLattice(24, 20, kRadius);  // ~850 triangle domains
  ASSERT_TRUE(packing.ok());
  CheckCascade(*packing, 0.2, 29, 3);
}

// Regression: when every loop contact of a domain breaks in the same re-detection (here the four of
// one interior square-lattice domain, which merges with its four neighbours), RemapPressures once
// found no half-edge of that domain in the new network and dropped its fluid. Lost contacts now
// join the old faces on their two sides.
TEST(Stability, MergeOfDomainThatLosesAllItsContactsConservesFluid) {
  auto packing = SquareLattice(6, 6, kRadius);
  ASSERT_TRUE(packing.ok());
  ContactList contacts;
  ContactDetector detector;
  ASSERT_TRUE(detector.Detect(*packing, 1e-12, &contacts).ok());
  const DomainNetwork before = Detect(*packing, contacts);
  // The domain at cell (2, 2): its loop contacts are its four sides.
  std::int32_t centre = -1;
  for (std::size_t k = 0; k < before.num_domains(); ++k) {
    if (std::abs(before.centroid_x[k] - 6 * kRadius) < 1e-9 &&
        std::abs(before.centroid_y[k] - 6 * kRadius) < 1e-9) {
      centre = static_cast<std::int32_t>(k);
    }
  }
  ASSERT_GE(centre, 0);
  std::vector<std::uint8_t> removed(contacts.size(), 0);
  for (std::int32_t k = before.loop_offsets[centre]; k < before.loop_offsets[centre + 1]; ++k) {
    removed[static_cast<std::size_t>(before.loop_contacts[k])] = 1;
  }
  const DomainNetwork after = Detect(*packing, Keep(contacts, removed));
  ASSERT_EQ(after.num_domains(), before.num_domains() - 4);
  std::vector<double> p(before.num_domains(), 0.0);
  p[static_cast<std::size_t>(centre)] = 1e6;  // all the excess fluid sits in the vanishing domain
  std::vector<double> q;
  const auto r = RemapPressures(before, p, after, {}, &q);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->unmatched_old, 0);
  EXPECT_NEAR(SumsOf(after, q).stored / SumsOf(before, p).stored, 1.0, 1e-12);
}

}  // namespace
}  // namespace seep::core
