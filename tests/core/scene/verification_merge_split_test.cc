// V16 (docs/physics.md §2.6, §5): a contact between two domains is removed (the two domains merge)
// and re-formed (the merged domain splits); RemapPressures carries the pressures across conserving
// the stored fluid sum V_s P.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "scene_test_util.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/domain_walls.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/network/pressure_remap.h"
#include "seep/core/network/scene_network.h"

namespace seep::core {
namespace {

ContactList Without(const ContactList& contacts, std::size_t removed) {
  ContactList out;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (c == removed) continue;
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

// Deterministic, uneven pressures: 1e5 Pa times a fixed pseudo-random pattern in [0.5, 1.5).
std::vector<double> Pressures(std::size_t n) {
  std::vector<double> p(n);
  std::uint64_t state = 12345;
  for (double& v : p) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    v = 1e5 * (0.5 + static_cast<double>(state >> 11) / 9007199254740992.0);
  }
  return p;
}

double Stored(const DomainNetwork& d, const std::vector<double>& p) {
  double s = 0.0;
  for (std::size_t k = 0; k < d.num_domains(); ++k) s += d.pore_volume[k] * p[k];
  return s;
}

std::vector<double> Remap(const DomainNetwork& from, const std::vector<double>& p,
                          const DomainNetwork& to, PressureRemapReport* report) {
  std::vector<double> out;
  auto r = RemapPressures(from, p, to, {}, &out);
  EXPECT_TRUE(r.ok()) << r.status().ToString();
  if (r.ok()) *report = *r;
  return out;
}

void CheckMergeAndSplit(const Packing& packing, const ContactList& contacts, std::size_t pipe) {
  const DomainNetwork before = Detect(packing, contacts);
  const std::vector<double> p = Pressures(before.num_domains());
  const auto c = static_cast<std::size_t>(before.pipe_contact[pipe]);
  const auto d1 = static_cast<std::size_t>(before.pipe_domain_a[pipe]);
  const auto d2 = static_cast<std::size_t>(before.pipe_domain_b[pipe]);
  const double v1 = before.pore_volume[d1];
  const double v2 = before.pore_volume[d2];
  const double merged_expected = (v1 * p[d1] + v2 * p[d2]) / (v1 + v2);

  // Merge.
  const DomainNetwork merged = Detect(packing, Without(contacts, c));
  ASSERT_EQ(merged.num_domains(), before.num_domains() - 1);
  PressureRemapReport report;
  const std::vector<double> pm = Remap(before, p, merged, &report);
  EXPECT_EQ(report.unmatched_new, 0);
  EXPECT_EQ(report.unmatched_old, 0);
  EXPECT_EQ(report.clusters, static_cast<std::int32_t>(merged.num_domains()));
  EXPECT_NEAR(Stored(merged, pm) / Stored(before, p), 1.0, 1e-12);
  EXPECT_NEAR(report.new_stored / report.old_stored, 1.0, 1e-12);
  // The merged domain is the one whose pressure is neither old value; every other domain keeps
  // its own pressure exactly (checked as a multiset via the sum of the others).
  std::size_t merged_id = merged.num_domains();
  for (std::size_t k = 0; k < merged.num_domains(); ++k) {
    if (std::abs(merged.pore_volume[k] - (v1 + v2)) <= 1e-12 * (v1 + v2) &&
        std::abs(pm[k] - merged_expected) <= 1e-12 * merged_expected) {
      merged_id = k;
    }
  }
  ASSERT_LT(merged_id, merged.num_domains()) << "no domain of volume V1 + V2 at the mean P";
  double others_before = 0.0;
  for (std::size_t k = 0; k < before.num_domains(); ++k) {
    if (k != d1 && k != d2) others_before += p[k];
  }
  double others_after = 0.0;
  for (std::size_t k = 0; k < merged.num_domains(); ++k) {
    if (k != merged_id) others_after += pm[k];
  }
  EXPECT_NEAR(others_after / others_before, 1.0, 1e-14);

  // Split: the contact forms again; both children start at the merged pressure.
  const DomainNetwork split = Detect(packing, contacts);
  const std::vector<double> ps = Remap(merged, pm, split, &report);
  ASSERT_EQ(split.num_domains(), before.num_domains());
  EXPECT_EQ(ps[d1], pm[merged_id]);
  EXPECT_EQ(ps[d2], pm[merged_id]);
  EXPECT_NEAR(Stored(split, ps) / Stored(merged, pm), 1.0, 1e-12);
  for (std::size_t k = 0; k < split.num_domains(); ++k) {
    if (k != d1 && k != d2) {
      EXPECT_EQ(ps[k], p[k]) << "domain " << k;
    }
  }
}

TEST(Verification, V16_MergeSplitConservation) {
  {
    SCOPED_TRACE("hex lattice");
    auto packing = HexLattice(12, 10, 1e-3);
    ASSERT_TRUE(packing.ok());
    ContactDetector detector;
    ContactList contacts;
    ASSERT_TRUE(detector.Detect(*packing, 1e-12, &contacts).ok());
    const DomainNetwork d = Detect(*packing, contacts);
    CheckMergeAndSplit(*packing, contacts, d.num_pipes() / 2);
  }
  {
    SCOPED_TRACE("random packing");
    auto net = BuildSceneNetwork(scene_test::RandomScene(7));
    ASSERT_TRUE(net.ok()) << net.status().ToString();
    for (std::size_t pipe :
         {std::size_t{0}, net->domains.num_pipes() / 3, net->domains.num_pipes() - 1}) {
      SCOPED_TRACE(testing::Message() << "pipe " << pipe);
      CheckMergeAndSplit(net->packing, net->contacts, pipe);
    }
  }
}

TEST(PressureRemap, UnchangedNetworkKeepsEveryPressure) {
  auto net = BuildSceneNetwork(scene_test::RandomScene(3));
  ASSERT_TRUE(net.ok()) << net.status().ToString();
  const std::vector<double> p = Pressures(net->domains.num_domains());
  PressureRemapReport report;
  EXPECT_EQ(Remap(net->domains, p, net->domains, &report), p);
  EXPECT_EQ(report.clusters, static_cast<std::int32_t>(net->domains.num_domains()));
}

TEST(PressureRemap, RejectsTooFewPressures) {
  auto net = BuildSceneNetwork(scene_test::RandomScene(3));
  ASSERT_TRUE(net.ok()) << net.status().ToString();
  std::vector<double> out;
  const std::vector<double> p(net->domains.num_domains() - 1, 0.0);
  auto r = RemapPressures(net->domains, p, net->domains, {}, &out);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(r.status().message().rfind("remap.old_pressure:", 0), 0u) << r.status().message();
}

}  // namespace
}  // namespace seep::core

namespace seep::core {
namespace {

// A pocket born by a re-detection takes the pressure of what it opened into: the
// conductance-weighted mean of the fixed nodes it reaches, else of its neighbours that are not
// pockets; a pocket beside another pocket ignores it, and one with neither keeps its value.
// Nodes: 0 fixed at 1e5, 1 fixed at 3e5, 2 free at 7e4, pockets 3 (pipes to 0, 1, 2 and 4),
// 4 (pipes to 2 and 3), 5 (no pipes).
TEST(PocketPressures, TakeWhatThePocketOpenedInto) {
  FlowNetworkData data;
  data.apparent_volume = {0, 0, 1, 1, 1, 1};
  data.pore_volume = {0, 0, 1, 1, 1, 1};
  data.pressure = {1e5, 3e5, 7e4, -1.0, -2.0, 42.0};
  data.role = {DomainRole::kFixedPressure, DomainRole::kFixedPressure, DomainRole::kFree,
               DomainRole::kFree,          DomainRole::kFree,          DomainRole::kFree};
  data.source_rate.assign(6, 0.0);
  data.pipe_domain_a = {3, 1, 3, 4, 4};
  data.pipe_domain_b = {0, 3, 2, 2, 3};
  data.pipe_length.assign(5, 1.0);
  data.pipe_aperture.assign(5, 1e-6);
  data.pipe_conductance = {1.0, 3.0, 5.0, 2.0, 7.0};
  auto flow = FlowNetwork::Create(data);
  ASSERT_TRUE(flow.ok()) << flow.status().message();
  std::vector<double> pressure = data.pressure;
  const std::vector<std::int32_t> pockets = {3, 4, 5};
  PocketPressures(*flow, pockets, pressure);
  EXPECT_DOUBLE_EQ(pressure[3], (1.0 * 1e5 + 3.0 * 3e5) / 4.0);  // the fixed nodes only
  EXPECT_DOUBLE_EQ(pressure[4], 7e4);                            // node 2; pocket 3 ignored
  EXPECT_EQ(pressure[5], 42.0);
  EXPECT_EQ(pressure[2], 7e4);  // not a pocket: untouched
}

// A network the matching cannot index is refused naming the field, before anything is written.
TEST(PressureRemap, RejectsLoopsItCannotIndex) {
  auto net = BuildSceneNetwork(scene_test::RandomScene(3));
  ASSERT_TRUE(net.ok()) << net.status().ToString();
  const DomainNetwork& good = net->domains;
  const std::vector<double> p = Pressures(good.num_domains());
  const auto refused = [&](const DomainNetwork& old_network, const DomainNetwork& new_network,
                           const std::string& prefix) {
    std::vector<double> out = {7.0};
    const auto r = RemapPressures(old_network, p, new_network, {}, &out);
    ASSERT_FALSE(r.ok()) << prefix;
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(r.status().message().rfind(prefix, 0), 0u) << r.status().message();
    EXPECT_EQ(out, std::vector<double>{7.0});
  };
  DomainNetwork negative = good;
  negative.loop_particles[5] = -1;
  refused(negative, good, "remap.old_network.loop_particles[5]: -1 is neither a particle");
  DomainNetwork no_wall = good;  // no walls: ids from DomainWalls::num_particles on are walls
  no_wall.walls.num_particles = static_cast<std::int32_t>(net->packing.size());
  no_wall.loop_particles[2] = no_wall.walls.num_particles;
  refused(good, no_wall, "remap.new_network.loop_particles[2]: ");
  DomainNetwork short_offsets = good;
  short_offsets.loop_offsets.back() -= 1;
  refused(short_offsets, good, "remap.old_network.loop_particles: offsets do not end");
  ASSERT_GT(good.num_outer_faces(), 0u);  // the packing's outer walk at least
  DomainNetwork host = good;
  host.outer_host_domain[0] = static_cast<std::int32_t>(good.num_domains());
  refused(good, host, "remap.new_network.outer_host_domain[0]: ");
}

// A wall vertex's id depends on what else touches the walls: a foot that leaves the floor drops its
// vertex and renumbers the ones after it. The remap must match wall vertices by what they are:
// the two floor pores beside the lost foot merge, and every other domain keeps its pressure
// exactly (with ids matched, a shifted vertex would tie unrelated domains together).
TEST(PressureRemap, WallVerticesAreMatchedByWhatTheyAre) {
  const double R = 1e-3;
  const Result<Packing> lattice = SquareLattice(3, 3, R);
  ASSERT_TRUE(lattice.ok());
  const Packing& p = *lattice;
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (std::size_t i = 0; i < p.size(); ++i) {
    x0 = std::min(x0, p.x[i] - p.radius[i]);
    y0 = std::min(y0, p.y[i] - p.radius[i]);
    x1 = std::max(x1, p.x[i] + p.radius[i]);
    y1 = std::max(y1, p.y[i] + p.radius[i]);
  }
  const std::vector<WallLine> lines = {
      {x0, y0, 1.0, 0.0}, {x1, y0, -1.0, 0.0}, {x0, y0, 0.0, 1.0}, {x0, y1, 0.0, -1.0}};
  const double max_gap = 1e-9 * R;
  const Result<ContactList> contacts = DetectContacts(p, max_gap);
  ASSERT_TRUE(contacts.ok());
  const WallContactList feet = FindWallContacts(p, lines, max_gap);
  const auto detect = [&](const WallContactList& wall_contacts) {
    DomainDetector detector;
    DomainNetwork net;
    const Status s =
        detector.Detect(p, *contacts, ClipWalls(p, lines), wall_contacts, {max_gap}, &net);
    EXPECT_TRUE(s.ok()) << s.ToString();
    return net;
  };
  // The floor's middle foot: the lowest particle nearest the middle.
  std::size_t lost = feet.size();
  for (std::size_t k = 0; k < feet.size(); ++k) {
    const auto i = static_cast<std::size_t>(feet.particle[k]);
    if (feet.wall[k] == 2 && std::abs(p.x[i] - 0.5 * (x0 + x1)) < 0.5 * R) lost = k;
  }
  ASSERT_LT(lost, feet.size());
  WallContactList fewer = feet;
  const auto at = static_cast<std::ptrdiff_t>(lost);
  fewer.particle.erase(fewer.particle.begin() + at);
  fewer.wall.erase(fewer.wall.begin() + at);
  fewer.gap.erase(fewer.gap.begin() + at);
  const DomainNetwork before = detect(feet);
  const DomainNetwork after = detect(fewer);
  ASSERT_EQ(before.num_domains(), 16u);
  ASSERT_EQ(after.num_domains(), 15u);
  ASSERT_EQ(after.walls.num_vertices() + 1, before.walls.num_vertices());

  const std::vector<double> pressure = Pressures(before.num_domains());
  PressureRemapReport report;
  const std::vector<double> remapped = Remap(before, pressure, after, &report);
  ASSERT_EQ(remapped.size(), after.num_domains());
  EXPECT_EQ(report.unmatched_new, 0);
  EXPECT_EQ(report.unmatched_old, 0);
  EXPECT_EQ(report.clusters, 15);
  EXPECT_NEAR(report.new_stored / report.old_stored, 1.0, 1e-12);
  // Each new domain against the old ones at its centroid (a vertex apart at most is 1e-9 R).
  std::vector<std::size_t> merged_from;
  for (std::size_t e = 0; e < after.num_domains(); ++e) {
    std::size_t same = before.num_domains();
    for (std::size_t d = 0; d < before.num_domains(); ++d) {
      if (std::hypot(before.centroid_x[d] - after.centroid_x[e],
                     before.centroid_y[d] - after.centroid_y[e]) < 1e-9 * R) {
        same = d;
      }
    }
    if (same < before.num_domains()) {
      EXPECT_EQ(remapped[e], pressure[same]) << "domain " << e;
      continue;
    }
    // The merged floor pore: the V_p-weighted mean of the two it replaced (the old domains
    // whose centroids lie on the floor within 2R of the lost foot's particle).
    double stored = 0.0, volume = 0.0;
    const auto i = static_cast<std::size_t>(feet.particle[lost]);
    for (std::size_t d = 0; d < before.num_domains(); ++d) {
      if (before.centroid_y[d] < p.y[i] && std::abs(before.centroid_x[d] - p.x[i]) < 2 * R) {
        stored += before.pore_volume[d] * pressure[d];
        volume += before.pore_volume[d];
        merged_from.push_back(d);
      }
    }
    EXPECT_NEAR(remapped[e], stored / volume, 1e-14 * stored / volume);
  }
  EXPECT_EQ(merged_from.size(), 2u);
}

}  // namespace
}  // namespace seep::core
