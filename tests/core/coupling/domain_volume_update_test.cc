// Domain volumes on a fixed topology from moved particles (docs/physics.md §2.7 step 4) and dV.
#include "seep/core/coupling/domain_volume_update.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "coupling_test_util.h"

namespace seep::core {
namespace {

using coupling_test::Detect;
using coupling_test::Detected;

struct Volumes {
  std::vector<double> apparent, pore;
};

Volumes ComputeAt(const DomainVolumeUpdater& updater, const Packing& packing,
                  const DomainNetwork& network) {
  Volumes v{std::vector<double>(network.num_domains()), std::vector<double>(network.num_domains())};
  const Status s = updater.Compute(ViewOf(packing), network, v.apparent, v.pore);
  EXPECT_TRUE(s.ok()) << s.ToString();
  return v;
}

double MaxAbs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

// A hex lattice squeezed to 95 % of its spacing: overlaps of 10 % of R, whose lenses (chord
// half-length 0.31 R) are beyond the updater's short series and take LensArea.
Packing SqueezedHex() {
  const Packing hex = coupling_test::Hex(9, 7, 1e-3);
  Packing out;
  for (std::size_t i = 0; i < hex.size(); ++i)
    out.Add(0.95 * hex.x[i], 0.95 * hex.y[i], hex.radius[i]);
  return out;
}

// The test packings: lattices (no rattlers; one with deep overlaps) and a random packing with
// rattlers.
std::vector<std::pair<std::string, Detected>> Cases() {
  std::vector<std::pair<std::string, Detected>> cases;
  cases.emplace_back("square", Detect(coupling_test::Square(8, 6, 1e-3)));
  cases.emplace_back("hex", Detect(coupling_test::Hex(9, 7, 1e-3)));
  cases.emplace_back("squeezed hex", Detect(SqueezedHex()));
  cases.emplace_back("random", Detect(coupling_test::Random(3), 1e-2));
  return cases;
}

// At the detection positions the loop formulas redo the detector's arithmetic: agreement to
// round-off (1e-12 relative to the domain's V_d; the V_p of a triangle is 0.09 V_d, so a few
// 1e-16 V_d of cancellation stays far below).
TEST(DomainVolumeUpdate, MatchesDetectionAtDetectedPositions) {
  for (const auto& [name, d] : Cases()) {
    SCOPED_TRACE(name);
    DomainVolumeUpdater updater;
    ASSERT_TRUE(updater.Bind(ViewOf(d.packing), d.domains).ok());
    const Volumes v = ComputeAt(updater, d.packing, d.domains);
    for (std::size_t k = 0; k < d.domains.num_domains(); ++k) {
      const double vd = d.domains.apparent_volume[k];
      EXPECT_NEAR(v.apparent[k], vd, 1e-12 * vd) << "domain " << k;
      EXPECT_NEAR(v.pore[k], d.domains.pore_volume[k], 1e-12 * vd) << "domain " << k;
    }
    if (name != "random") {
      // No rattlers: the correction is round-off only.
      double max_vd = 0.0;
      for (double vd : d.domains.apparent_volume) max_vd = std::max(max_vd, vd);
      EXPECT_LT(MaxAbs(std::vector<double>(updater.rattler_correction().begin(),
                                           updater.rattler_correction().end())),
                1e-13 * max_vd);
    }
  }
}

Packing Transformed(const Packing& p, double cos_a, double sin_a, double tx, double ty,
                    double scale, bool scale_radii) {
  Packing out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    out.Add(scale * (cos_a * p.x[i] - sin_a * p.y[i]) + tx,
            scale * (sin_a * p.x[i] + cos_a * p.y[i]) + ty,
            scale_radii ? scale * p.radius[i] : p.radius[i]);
  }
  return out;
}

// A rigid motion changes no area: dV_d = dV_p = 0 to round-off. The shoelace works relative to
// the loop's first centre and the angles are differences, so the error is ~1e-16 of the
// coordinates' span over R, i.e. ~1e-14 V relative here; 1e-12 is the asserted bound.
TEST(DomainVolumeUpdate, RigidMotionGivesZeroVolumeChange) {
  for (const auto& [name, d] : Cases()) {
    SCOPED_TRACE(name);
    DomainVolumeUpdater updater;
    ASSERT_TRUE(updater.Bind(ViewOf(d.packing), d.domains).ok());
    const Volumes before = ComputeAt(updater, d.packing, d.domains);
    // Edge turns inside the updater's short series (1e-6, 0.03 rad) and beyond it (0.7 rad: atan2).
    for (const double angle : {1e-6, 0.03, 0.7}) {
      SCOPED_TRACE(angle);
      const double r = d.packing.radius[0];
      const Packing moved =
          Transformed(d.packing, std::cos(angle), std::sin(angle), 13.3 * r, -4.1 * r, 1.0, false);
      const Volumes after = ComputeAt(updater, moved, d.domains);
      std::vector<double> dvd(before.apparent.size()), dvp(before.apparent.size());
      ASSERT_TRUE(ComputeVolumeChange(before.apparent, after.apparent, dvd).ok());
      ASSERT_TRUE(ComputeVolumeChange(before.pore, after.pore, dvp).ok());
      for (std::size_t k = 0; k < dvd.size(); ++k) {
        EXPECT_NEAR(dvd[k], 0.0, 1e-12 * before.apparent[k]) << "domain " << k;
        EXPECT_NEAR(dvp[k], 0.0, 1e-12 * before.apparent[k]) << "domain " << k;
      }
    }
  }
}

// Uniform isotropic expansion about the origin by s: every centre polygon scales by s^2 (the
// radii stay, as for a skeleton whose contacts open). Relative 1e-12: each coordinate carries
// one rounding of the scaling, ~1e-16 relative.
TEST(DomainVolumeUpdate, IsotropicExpansionScalesApparentVolumeBySSquared) {
  constexpr double kS = 1.0137;
  for (const auto& [name, d] : Cases()) {
    SCOPED_TRACE(name);
    DomainVolumeUpdater updater;
    ASSERT_TRUE(updater.Bind(ViewOf(d.packing), d.domains).ok());
    const Volumes before = ComputeAt(updater, d.packing, d.domains);
    const Volumes after =
        ComputeAt(updater, Transformed(d.packing, 1.0, 0.0, 0.0, 0.0, kS, false), d.domains);
    std::vector<double> dvd(before.apparent.size());
    ASSERT_TRUE(ComputeVolumeChange(before.apparent, after.apparent, dvd).ok());
    for (std::size_t k = 0; k < dvd.size(); ++k) {
      EXPECT_NEAR(after.apparent[k] / before.apparent[k], kS * kS, 1e-12) << "domain " << k;
      EXPECT_NEAR(dvd[k], (kS * kS - 1.0) * before.apparent[k], 1e-12 * before.apparent[k]);
    }
  }
}

// Scaling centres and radii together is a similarity: V_p scales by s^2 as well (sectors keep
// their angles, lenses scale as areas). Domains holding rattlers carry a fixed correction (see
// the header), so they are left out on the random packing.
TEST(DomainVolumeUpdate, SimilarityScalesPoreVolumeBySSquared) {
  constexpr double kS = 0.9731;
  for (const auto& [name, d] : Cases()) {
    SCOPED_TRACE(name);
    DomainVolumeUpdater updater;
    ASSERT_TRUE(updater.Bind(ViewOf(d.packing), d.domains).ok());
    const Volumes before = ComputeAt(updater, d.packing, d.domains);
    const Volumes after =
        ComputeAt(updater, Transformed(d.packing, 1.0, 0.0, 0.0, 0.0, kS, true), d.domains);
    std::size_t checked = 0;
    for (std::size_t k = 0; k < before.pore.size(); ++k) {
      if (std::abs(updater.rattler_correction()[k]) > 1e-12 * before.apparent[k]) continue;
      ++checked;
      // V_p is a difference of V_d and sectors (V_p/V_d ~ 0.1-0.2): 1e-12 of V_d.
      EXPECT_NEAR(after.pore[k], kS * kS * before.pore[k], 1e-12 * before.apparent[k])
          << "domain " << k;
    }
    EXPECT_GT(checked, before.pore.size() / 2);
  }
}

// After a small affine strain (no contact lost, angular orders unchanged), re-detection with the
// same contact pairs finds the same domains; the updated volumes must equal its volumes
// (domains without rattlers: the rattler correction is frozen by design).
TEST(DomainVolumeUpdate, MatchesRedetectionAfterAffineStrain) {
  for (const auto& [name, d] : Cases()) {
    SCOPED_TRACE(name);
    DomainVolumeUpdater updater;
    ASSERT_TRUE(updater.Bind(ViewOf(d.packing), d.domains).ok());
    Packing strained;
    for (std::size_t i = 0; i < d.packing.size(); ++i) {
      const double x = d.packing.x[i], y = d.packing.y[i];
      strained.Add(x * (1.0 + 2e-3) + 1.5e-3 * y, y * (1.0 - 1e-3) + 0.5e-3 * x,
                   d.packing.radius[i]);
    }
    ContactList same_pairs = d.contacts;
    for (std::size_t c = 0; c < same_pairs.size(); ++c) {
      const auto i = static_cast<std::size_t>(same_pairs.i[c]);
      const auto j = static_cast<std::size_t>(same_pairs.j[c]);
      same_pairs.gap[c] = std::hypot(strained.x[j] - strained.x[i], strained.y[j] - strained.y[i]) -
                          strained.radius[i] - strained.radius[j];
    }
    auto redetected = DetectDomains(strained, same_pairs);
    ASSERT_TRUE(redetected.ok());
    ASSERT_EQ(redetected->loop_particles, d.domains.loop_particles);
    const Volumes v = ComputeAt(updater, strained, d.domains);
    for (std::size_t k = 0; k < v.apparent.size(); ++k) {
      const double vd = redetected->apparent_volume[k];
      EXPECT_NEAR(v.apparent[k], vd, 1e-12 * vd) << "domain " << k;
      if (std::abs(updater.rattler_correction()[k]) > 1e-12 * vd) continue;
      EXPECT_NEAR(v.pore[k], redetected->pore_volume[k], 1e-12 * vd) << "domain " << k;
    }
  }
}

// An island (a triangle of disks inside a ring of 16): the host domain's V_d is the ring polygon
// minus the triangle, its V_p also loses the ring's sectors and the triangle's solid outside its
// polygon (three 300-degree sectors). Exact in closed form; moving the island rigidly inside its
// host changes nothing, and pulling its disks apart takes the extra triangle area from the host.
TEST(DomainVolumeUpdate, IslandInsideItsHostDomain) {
  constexpr double kR = 1e-3;
  constexpr int kRing = 16;
  const double pi = std::numbers::pi;
  Packing p;
  coupling_test::AddRing(&p, kRing, kR);
  coupling_test::AddTriangle(&p, 0.0, 0.0, kR, 0.3);
  const Detected d = Detect(p);
  ASSERT_EQ(d.domains.num_domains(), 2u);
  ASSERT_EQ(d.domains.num_outer_faces(), 2u);
  const std::size_t host = d.domains.apparent_volume[0] > d.domains.apparent_volume[1] ? 0 : 1;
  const double ring_radius = kR / std::sin(pi / kRing);
  const double ring_area = 0.5 * kRing * ring_radius * ring_radius * std::sin(2.0 * pi / kRing);
  const double triangle = std::sqrt(3.0) * kR * kR;
  const double host_vd = ring_area - triangle;
  const double host_vp = host_vd - 0.5 * (kRing - 2) * pi * kR * kR - 2.5 * pi * kR * kR;

  DomainVolumeUpdater updater;
  ASSERT_TRUE(updater.Bind(ViewOf(d.packing), d.domains).ok());
  const Volumes v = ComputeAt(updater, d.packing, d.domains);
  // Closed forms against the loop sums of 16 + 3 terms: 1e-12 of V_d.
  EXPECT_NEAR(v.apparent[host], host_vd, 1e-12 * host_vd);
  EXPECT_NEAR(v.pore[host], host_vp, 1e-12 * host_vd);
  EXPECT_NEAR(v.apparent[1 - host], triangle, 1e-12 * triangle);
  EXPECT_NEAR(v.apparent[host], d.domains.apparent_volume[host], 1e-12 * host_vd);
  EXPECT_NEAR(v.pore[host], d.domains.pore_volume[host], 1e-12 * host_vd);

  Packing moved;
  coupling_test::AddRing(&moved, kRing, kR);
  coupling_test::AddTriangle(&moved, 0.4 * kR, -0.7 * kR, kR, 1.1);
  const Volumes after_move = ComputeAt(updater, moved, d.domains);
  EXPECT_NEAR(after_move.apparent[host], host_vd, 1e-12 * host_vd);
  EXPECT_NEAR(after_move.pore[host], host_vp, 1e-12 * host_vd);

  // Triangle disks pushed 1% further from its centre: side 2R -> 2.02R, contacts open.
  Packing opened;
  coupling_test::AddRing(&opened, kRing, kR);
  coupling_test::AddTriangle(&opened, 0.0, 0.0, kR * 1.01, 0.3);
  for (std::size_t i = kRing; i < opened.size(); ++i) opened.radius[i] = kR;
  const Volumes after_open = ComputeAt(updater, opened, d.domains);
  const double grown = triangle * 1.01 * 1.01;
  EXPECT_NEAR(after_open.apparent[1 - host], grown, 1e-12 * triangle);
  EXPECT_NEAR(after_open.apparent[host], ring_area - grown, 1e-12 * host_vd);
  // The solid outside the island's polygon is still three 300-degree sectors.
  EXPECT_NEAR(after_open.pore[host], host_vp - (grown - triangle), 1e-12 * host_vd);
}

TEST(DomainVolumeUpdate, RejectsAnotherNetworkAndBadSizes) {
  const Detected small = Detect(coupling_test::Square(3, 3, 1.0));
  const Detected large = Detect(coupling_test::Square(4, 4, 1.0));
  DomainVolumeUpdater updater;
  ASSERT_TRUE(updater.Bind(ViewOf(small.packing), small.domains).ok());
  std::vector<double> a(large.domains.num_domains()), p(large.domains.num_domains());
  EXPECT_EQ(updater.Compute(ViewOf(large.packing), large.domains, a, p).code(),
            StatusCode::kFailedPrecondition);
  std::vector<double> short_a(small.domains.num_domains() - 1), short_p(short_a.size());
  EXPECT_EQ(updater.Compute(ViewOf(small.packing), small.domains, short_a, short_p).code(),
            StatusCode::kInvalidArgument);
  std::vector<double> change(2);
  const std::vector<double> before(3), after(3);
  EXPECT_EQ(ComputeVolumeChange(before, after, change).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace seep::core
