// Domain detection on awkward inputs: rattlers, dangling chains, separate clusters, islands,
// overlapping disks, collinear particles, bad contact lists and workspace reuse.
#include <gtest/gtest.h>

#include <cmath>

#include "geometry_test_util.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"

namespace seep::core {
namespace {

using testing::kPi;

// n equal disks of radius R touching in a ring centred at (cx, cy).
void AddRing(Packing* p, int n, double R, double cx, double cy) {
  const double rho = R / std::sin(kPi / n);
  for (int k = 0; k < n; ++k) {
    p->Add(cx + rho * std::cos(2 * kPi * k / n), cy + rho * std::sin(2 * kPi * k / n), R);
  }
}

double RingPolygonArea(int n, double R) {
  const double rho = R / std::sin(kPi / n);
  return 0.5 * n * rho * rho * std::sin(2 * kPi / n);
}

DomainNetwork Detect(const Packing& p, double max_gap) {
  const Result<ContactList> contacts = DetectContacts(p, max_gap);
  EXPECT_TRUE(contacts.ok());
  Result<DomainNetwork> net = DetectDomains(p, *contacts);
  EXPECT_TRUE(net.ok()) << net.status().ToString();
  return std::move(net).value();
}

TEST(DomainRobustness, RattlerAndOutwardChainArePruned) {
  const double R = 1.0;
  Packing p = SquareLattice(3, 3, R).value();
  // A rattler in the lower-left square hole (the hole fits radius (sqrt2 - 1) R).
  const double rattler = 0.3 * R;
  p.Add(2 * R, 2 * R, rattler);
  // A chain of three disks hanging off the top-right corner, outside the lattice.
  p.Add(7 * R, 5 * R, R);
  p.Add(9 * R, 5 * R, R);
  p.Add(11 * R, 5 * R, R);
  const DomainNetwork net = Detect(p, 1e-9);
  EXPECT_EQ(net.num_pruned_particles, 4);
  EXPECT_EQ(net.euler.vertices, 9);
  EXPECT_EQ(net.euler.edges, 12);
  EXPECT_EQ(net.num_domains(), 4u);
  EXPECT_TRUE(testing::EulerHolds(net));
  // Domain 0 is the lower-left square (it owns the first half-edge, particle 0 -> 1).
  EXPECT_NEAR(net.apparent_volume[0], 4 * R * R, 1e-12);
  EXPECT_NEAR(net.pore_volume[0], (4 - kPi) * R * R - kPi * rattler * rattler, 1e-12);
  for (std::size_t d = 1; d < 4; ++d) EXPECT_NEAR(net.pore_volume[d], (4 - kPi) * R * R, 1e-12);
}

TEST(DomainRobustness, ManyFreeRattlersAreLocated) {
  // One rattler in each of 81 square holes: enough queries to switch point location from a scan
  // to the grid. Radii vary so that a rattler given to the wrong domain is noticed.
  const int n = 10;
  const double R = 1.0;
  Packing p = SquareLattice(n, n, R).value();
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i)
      p.Add((2 * i + 2) * R, (2 * j + 2) * R, 0.1 + 0.003 * (j * n + i));
  }
  const DomainNetwork net = Detect(p, 1e-9);
  ASSERT_EQ(net.num_domains(), 81u);
  EXPECT_EQ(net.num_pruned_particles, 81);
  for (std::size_t d = 0; d < net.num_domains(); ++d) {
    // The rattler of a domain sits at its centroid.
    double rattler = 0.0;
    for (std::size_t k = static_cast<std::size_t>(n * n); k < p.size(); ++k) {
      if (std::abs(p.x[k] - net.centroid_x[d]) < 1e-9 &&
          std::abs(p.y[k] - net.centroid_y[d]) < 1e-9) {
        rattler = p.radius[k];
      }
    }
    ASSERT_GT(rattler, 0.0) << "domain " << d;
    EXPECT_NEAR(net.pore_volume[d], (4 - kPi) * R * R - kPi * rattler * rattler, 1e-12);
  }
}

TEST(DomainRobustness, InwardDanglingChainIsSubtractedFromItsFace) {
  const int n = 12;
  const double R = 1.0;
  Packing p;
  AddRing(&p, n, R, 0, 0);
  const double rho = R / std::sin(kPi / n);
  p.Add(rho - 2 * R, 0, R);  // touches ring particle 0, nothing else
  p.Add(rho - 4 * R, 0, R);
  const DomainNetwork net = Detect(p, 1e-9);
  ASSERT_EQ(net.num_domains(), 1u);
  EXPECT_EQ(net.num_pruned_particles, 2);
  EXPECT_TRUE(testing::EulerHolds(net));
  const double polygon = RingPolygonArea(n, R);
  EXPECT_NEAR(net.apparent_volume[0], polygon, 1e-12 * polygon);
  // Interior angles of a regular n-gon sum to (n - 2) pi.
  const double expected_vp = polygon - (n - 2) * kPi * R * R / 2 - 2 * kPi * R * R;
  EXPECT_NEAR(net.pore_volume[0], expected_vp, 1e-12 * polygon);
  EXPECT_EQ(net.num_boundary_pipes(), static_cast<std::size_t>(n));
  EXPECT_EQ(net.num_pipes(), 0u);
}

TEST(DomainRobustness, TwoIsolatedClustersAreTwoComponents) {
  const double R = 0.5;
  Packing p = SquareLattice(3, 3, R).value();
  const Packing second = SquareLattice(3, 3, R).value();
  for (std::size_t k = 0; k < second.size(); ++k) p.Add(second.x[k] + 20, second.y[k], R);
  const DomainNetwork net = Detect(p, 1e-9);
  EXPECT_EQ(net.euler.components, 2);
  EXPECT_EQ(net.num_outer_faces(), 2u);
  EXPECT_EQ(net.num_domains(), 8u);
  EXPECT_TRUE(testing::EulerHolds(net));  // 18 - 24 + 10 = 4
  EXPECT_EQ(net.outer_host_domain[0], -1);
  EXPECT_EQ(net.outer_host_domain[1], -1);
  EXPECT_EQ(net.num_boundary_pipes(), 16u);
  EXPECT_EQ(net.num_pipes(), 8u);
  for (std::size_t b = 0; b < net.num_boundary_pipes(); ++b) {
    // Outer face 1 is the cluster shifted to x >= 20.
    EXPECT_EQ(net.boundary_pipe_outer_face[b], net.boundary_pipe_x[b] > 10 ? 1 : 0);
  }
  const double outer = 2 * (2 * R) * (2 * R) * 4;
  EXPECT_NEAR(testing::Sum(net.apparent_volume), outer, 1e-12 * outer);
}

TEST(DomainRobustness, IslandInsideAFaceIsSubtractedAndConnected) {
  const int n = 24;
  const double R = 1.0;
  Packing p;
  AddRing(&p, n, R, 0, 0);
  // A triangle of touching disks at the centre: a separate component inside the ring's face.
  const double h = 2 * R / std::sqrt(3.0);  // centre-to-vertex distance of the triangle
  for (int k = 0; k < 3; ++k) {
    p.Add(h * std::cos(kPi / 2 + 2 * kPi * k / 3), h * std::sin(kPi / 2 + 2 * kPi * k / 3), R);
  }
  const DomainNetwork net = Detect(p, 1e-9);
  ASSERT_EQ(net.euler.components, 2);
  ASSERT_EQ(net.num_domains(), 2u);
  EXPECT_TRUE(testing::EulerHolds(net));
  // Domain 0 is the ring's (traced first: lower particle ids), outer face 1 the triangle's.
  EXPECT_EQ(net.outer_host_domain[0], -1);
  EXPECT_EQ(net.outer_host_domain[1], 0);
  const double ring = RingPolygonArea(n, R);
  const double tri = std::sqrt(3.0) * R * R;
  EXPECT_NEAR(net.outer_area[1], tri, 1e-12);
  EXPECT_NEAR(net.apparent_volume[0], ring - tri, 1e-12 * ring);
  // Island solid outside its triangle: 3 disks minus their 60-degree sectors = 2.5 pi R^2.
  EXPECT_NEAR(net.pore_volume[0], ring - (n - 2) * kPi * R * R / 2 - tri - 2.5 * kPi * R * R,
              1e-12 * ring);
  EXPECT_NEAR(net.apparent_volume[1], tri, 1e-12);
  EXPECT_NEAR(net.pore_volume[1], tri - kPi / 2 * R * R, 1e-12);
  // The island's three hull contacts are pipes to the host; the ring's are boundary pipes.
  ASSERT_EQ(net.num_pipes(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(std::min(net.pipe_domain_a[k], net.pipe_domain_b[k]), 0);
    EXPECT_EQ(std::max(net.pipe_domain_a[k], net.pipe_domain_b[k]), 1);
  }
  EXPECT_EQ(net.num_boundary_pipes(), static_cast<std::size_t>(n));
  EXPECT_NEAR(testing::Sum(net.apparent_volume), ring, 1e-12 * ring);
  EXPECT_EQ(net.is_boundary[0], 1);
  EXPECT_EQ(net.is_boundary[1], 0);
}

TEST(DomainRobustness, OverlappingDisksCountEachLensOnce) {
  const double R = 1.0;
  const double spacing = 2 * R * 0.99;  // overlap of 0.02 R at every lattice contact
  Packing p;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) p.Add(i * spacing, j * spacing, R);
  }
  const DomainNetwork net = Detect(p, 1e-9);
  ASSERT_EQ(net.num_domains(), 9u);
  EXPECT_TRUE(testing::EulerHolds(net));
  const double lens = testing::SegmentLens(R, R, spacing);
  ASSERT_GT(lens, 0.0);
  for (std::size_t d = 0; d < net.num_domains(); ++d) {
    EXPECT_NEAR(net.apparent_volume[d], spacing * spacing, 1e-12);
    // Four sectors of pi/2 each; every edge's half lens inside this square was counted twice.
    EXPECT_NEAR(net.pore_volume[d], spacing * spacing - kPi * R * R + 4 * (lens / 2), 1e-12);
  }
}

TEST(DomainRobustness, StraightChainHasNoDomains) {
  Packing p;
  for (int k = 0; k < 10; ++k) p.Add(2.0 * k, 1.0, 1.0);  // collinear touching chain
  const DomainNetwork net = Detect(p, 1e-9);
  EXPECT_EQ(net.num_domains(), 0u);
  EXPECT_EQ(net.num_pruned_particles, 10);
  EXPECT_EQ(net.euler.components, 0);
  EXPECT_EQ(net.num_pipes() + net.num_boundary_pipes(), 0u);
}

TEST(DomainRobustness, CollinearOverlappingTripleIsDeterministic) {
  // Three mutually overlapping disks on one line: the "triangle" has zero area and two
  // neighbours of the end disks lie at exactly the same angle (tie broken by id).
  Packing p;
  p.Add(0.0, 0.0, 1.0);
  p.Add(0.9, 0.0, 1.0);
  p.Add(1.8, 0.0, 1.0);
  const Result<ContactList> contacts = DetectContacts(p, 0.0);
  ASSERT_TRUE(contacts.ok());
  ASSERT_EQ(contacts->size(), 3u);
  DomainDetector detector;
  DomainNetwork first, second;
  ASSERT_TRUE(detector.Detect(p, *contacts, {}, &first).ok());
  ASSERT_TRUE(detector.Detect(p, *contacts, {}, &second).ok());
  EXPECT_TRUE(testing::EulerHolds(first));
  EXPECT_EQ(first.euler.cycles, 2);
  EXPECT_EQ(first.num_domains(), 1u);
  EXPECT_EQ(first.num_nonpositive_domains, 1);
  EXPECT_EQ(first.loop_particles, second.loop_particles);
  EXPECT_EQ(first.loop_contacts, second.loop_contacts);
  EXPECT_EQ(first.pore_volume, second.pore_volume);
}

TEST(DomainRobustness, CollinearNeighboursInALoopGiveStraightAngles) {
  // A 3 x 2 rectangle of squares: the middle particles of the long sides are collinear with their
  // neighbours; their face angles are pi (outer) and pi/2 + pi/2 (two inner squares).
  const double R = 1.0;
  const Packing p = SquareLattice(3, 2, R).value();
  const DomainNetwork net = Detect(p, 1e-9);
  ASSERT_EQ(net.num_domains(), 2u);
  const double solid = testing::SolidInsideOuterLoops(p, DetectContacts(p, 1e-9).value(), net);
  // Inside the 4R x 2R rectangle: 4 corner quarter disks + 2 half disks.
  EXPECT_NEAR(solid, 2 * kPi * R * R, 1e-12);
  EXPECT_NEAR(testing::Sum(net.pore_volume), 8 * R * R - 2 * kPi * R * R, 1e-12);
}

TEST(DomainRobustness, RejectsUnsortedOrOutOfRangeContacts) {
  const Packing p = SquareLattice(2, 2, 1.0).value();
  ContactList bad;
  bad.i = {0, 0};
  bad.j = {2, 1};  // out of (i, j) order
  bad.gap = {0.0, 0.0};
  const Result<DomainNetwork> unsorted = DetectDomains(p, bad);
  ASSERT_FALSE(unsorted.ok());
  EXPECT_EQ(unsorted.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(unsorted.status().message().find("contact 1"), std::string::npos);
  bad.i = {0};
  bad.j = {7};
  bad.gap = {0.0};
  EXPECT_FALSE(DetectDomains(p, bad).ok());
}

TEST(DomainRobustness, MaxGapOptionSelectsEdges) {
  // The lattice contacts touch; with max_gap below -1e-6 none of them is an edge.
  const Packing p = SquareLattice(4, 4, 1.0).value();
  const ContactList contacts = DetectContacts(p, 1e-9).value();
  DomainDetectionOptions options;
  options.max_gap = -1e-6;
  const DomainNetwork none = DetectDomains(p, contacts, options).value();
  EXPECT_EQ(none.num_domains(), 0u);
  options.max_gap = 1e-6;
  EXPECT_EQ(DetectDomains(p, contacts, options)->num_domains(), 9u);
}

TEST(DomainRobustness, ReusedDetectorGivesTheSameNetwork) {
  const Packing a = HexLattice(12, 9, 1.0).value();
  Packing b = SquareLattice(5, 5, 0.5).value();
  b.Add(1.0, 1.0, 0.2);  // rattler: exercises the point-location buffers
  const ContactList ca = DetectContacts(a, 1e-9).value();
  const ContactList cb = DetectContacts(b, 1e-9).value();
  DomainDetector detector;
  DomainNetwork first, other, again;
  ASSERT_TRUE(detector.Detect(a, ca, {}, &first).ok());
  ASSERT_TRUE(detector.Detect(b, cb, {}, &other).ok());
  ASSERT_TRUE(detector.Detect(a, ca, {}, &again).ok());
  EXPECT_EQ(first.loop_offsets, again.loop_offsets);
  EXPECT_EQ(first.loop_particles, again.loop_particles);
  EXPECT_EQ(first.pore_volume, again.pore_volume);
  EXPECT_EQ(first.pipe_domain_a, again.pipe_domain_a);
  EXPECT_EQ(first.boundary_pipe_x, again.boundary_pipe_x);
  EXPECT_EQ(other.num_pruned_particles, 1);
}

}  // namespace
}  // namespace seep::core
