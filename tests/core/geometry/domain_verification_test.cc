// Verification V03 (docs/physics.md §5): domains and pipes of regular lattices against closed
// forms, and the conservation identities on a random packing.
#include <gtest/gtest.h>

#include <cmath>

#include "geometry_test_util.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/geometry/random_packing.h"

namespace seep::core {
namespace {

using testing::kPi;

TEST(Verification, V03_SquareLatticeDomains) {
  const int n = 9;
  const int m = 6;
  const double R = 0.37;
  const Result<Packing> lattice = SquareLattice(n, m, R);
  ASSERT_TRUE(lattice.ok()) << lattice.status().ToString();
  // Neighbours touch exactly (gap 0 up to rounding); diagonals are (2 sqrt2 - 2) R apart.
  const Result<ContactList> contacts = DetectContacts(*lattice, 1e-9 * R);
  ASSERT_TRUE(contacts.ok());
  const std::size_t edges = static_cast<std::size_t>(n * (m - 1) + m * (n - 1));
  ASSERT_EQ(contacts->size(), edges);

  const Result<DomainNetwork> net = DetectDomains(*lattice, *contacts);
  ASSERT_TRUE(net.ok()) << net.status().ToString();
  const std::size_t domains = static_cast<std::size_t>((n - 1) * (m - 1));
  const std::size_t hull = static_cast<std::size_t>(2 * (n - 1) + 2 * (m - 1));
  EXPECT_EQ(net->num_domains(), domains);
  EXPECT_EQ(net->num_pipes(), edges - hull);
  EXPECT_EQ(net->num_boundary_pipes(), hull);
  EXPECT_EQ(net->euler.vertices, n * m);
  EXPECT_EQ(net->euler.edges, static_cast<std::int64_t>(edges));
  EXPECT_EQ(net->euler.components, 1);
  EXPECT_TRUE(testing::EulerHolds(*net));
  EXPECT_EQ(net->num_pruned_particles, 0);

  std::size_t boundary_domains = 0;
  for (std::size_t d = 0; d < net->num_domains(); ++d) {
    EXPECT_EQ(net->loop_offsets[d + 1] - net->loop_offsets[d], 4);
    EXPECT_NEAR(net->apparent_volume[d], 4 * R * R, 1e-12 * 4 * R * R);
    EXPECT_NEAR(net->pore_volume[d], (4 - kPi) * R * R, 1e-12 * (4 - kPi) * R * R);
    boundary_domains += net->is_boundary[d];
  }
  EXPECT_EQ(boundary_domains, domains - static_cast<std::size_t>((n - 3) * (m - 3)));
  for (std::size_t p = 0; p < net->num_pipes(); ++p) {
    EXPECT_DOUBLE_EQ(net->pipe_length[p], 2 * R);
    EXPECT_NE(net->pipe_domain_a[p], net->pipe_domain_b[p]);
  }
  const double outer = (2 * (n - 1) * R) * (2 * (m - 1) * R);
  ASSERT_EQ(net->num_outer_faces(), 1u);
  EXPECT_NEAR(net->outer_area[0], outer, 1e-12 * outer);
  EXPECT_NEAR(testing::Sum(net->apparent_volume), outer, 1e-12 * outer);
}

TEST(Verification, V03_HexLatticeDomains) {
  const int nx = 11;
  const int ny = 8;
  const double R = 1.3;
  const Result<Packing> lattice = HexLattice(nx, ny, R);
  ASSERT_TRUE(lattice.ok());
  const Result<ContactList> contacts = DetectContacts(*lattice, 1e-9 * R);
  ASSERT_TRUE(contacts.ok());
  const std::size_t a = nx - 1;
  const std::size_t b = ny - 1;
  // Rows: nx-1 edges each; between two rows 2 nx - 1.
  const std::size_t edges = ny * a + b * (2 * nx - 1);
  ASSERT_EQ(contacts->size(), edges);

  const Result<DomainNetwork> net = DetectDomains(*lattice, *contacts);
  ASSERT_TRUE(net.ok());
  const std::size_t hull = 2 * a + 2 * b;
  EXPECT_EQ(net->num_domains(), 2 * a * b);
  EXPECT_EQ(net->num_pipes(), 3 * a * b - a - b);
  EXPECT_EQ(net->num_boundary_pipes(), hull);
  EXPECT_EQ(net->euler.vertices, nx * ny);
  EXPECT_EQ(net->euler.components, 1);
  EXPECT_TRUE(testing::EulerHolds(*net));

  const double vd = std::sqrt(3.0) * R * R;
  const double vp = (std::sqrt(3.0) - kPi / 2) * R * R;
  for (std::size_t d = 0; d < net->num_domains(); ++d) {
    EXPECT_EQ(net->loop_offsets[d + 1] - net->loop_offsets[d], 3);
    EXPECT_NEAR(net->apparent_volume[d], vd, 1e-12 * vd);
    EXPECT_NEAR(net->pore_volume[d], vp, 1e-12 * vp);
  }
  // Each row strip is a band of height sqrt3 R and mean width 2 (nx - 1) R.
  const double outer = b * (2.0 * a * R) * (std::sqrt(3.0) * R);
  EXPECT_NEAR(net->outer_area[0], outer, 1e-12 * outer);
  EXPECT_NEAR(testing::Sum(net->apparent_volume), outer, 1e-12 * outer);
}

RandomPackingOptions SmallRandomOptions() {
  RandomPackingOptions o;
  o.count = 500;
  o.radius_min = 0.6;
  o.radius_max = 1.0;
  o.width = 40;
  o.height = 40;
  o.seed = 20240611;
  o.porosity = 0.2;
  return o;
}

TEST(Verification, V03_RandomPackingDomains) {
  const RandomPackingOptions options = SmallRandomOptions();
  const Result<RandomPacking> generated = GenerateRandomPacking(options);
  ASSERT_TRUE(generated.ok()) << generated.status().ToString();
  const Packing& p = generated->packing;

  // Determinism from the seed: a second run is bit-identical, another seed is not.
  const Result<RandomPacking> again = GenerateRandomPacking(options);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->packing.x, p.x);
  EXPECT_EQ(again->packing.y, p.y);
  EXPECT_EQ(again->packing.radius, p.radius);
  RandomPackingOptions other = options;
  other.seed += 1;
  const Result<RandomPacking> different = GenerateRandomPacking(other);
  ASSERT_TRUE(different.ok());
  EXPECT_NE(different->packing.x, p.x);

  // Edges: touching within 1% of the mean radius (the generator leaves gaps of that order).
  const double max_gap = options.contact_gap_ratio * generated->mean_radius;
  const Result<ContactList> contacts = DetectContacts(p, max_gap);
  ASSERT_TRUE(contacts.ok());
  const Result<DomainNetwork> net = DetectDomains(p, *contacts);
  ASSERT_TRUE(net.ok());
  ASSERT_GT(net->num_domains(), 100u);
  EXPECT_TRUE(testing::EulerHolds(*net)) << net->euler.vertices << " " << net->euler.edges << " "
                                         << net->euler.cycles << " " << net->euler.components;
  EXPECT_EQ(net->num_outer_faces(), static_cast<std::size_t>(net->euler.components));

  const double outer = testing::SumTopLevelOuterArea(*net);
  const double sum_vd = testing::Sum(net->apparent_volume);
  EXPECT_NEAR(sum_vd, outer, 1e-12 * outer);

  const double solid = testing::SolidInsideOuterLoops(p, *contacts, *net);
  const double sum_vp = testing::Sum(net->pore_volume);
  EXPECT_NEAR(sum_vp, sum_vd - solid, 1e-12 * sum_vd);
  for (std::size_t d = 0; d < net->num_domains(); ++d) {
    EXPECT_GT(net->pore_volume[d], 0.0) << "domain " << d;
  }
}

}  // namespace
}  // namespace seep::core
