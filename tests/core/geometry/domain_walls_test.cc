// Domains closed by walls (docs/physics.md §2.4 option B): the pores between walls and the
// particles against them, against their closed-form areas on lattices in a box.
#include "seep/core/geometry/domain_walls.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "geometry_test_util.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"

namespace seep::core {
namespace {

using testing::kPi;

struct Box {
  double x0, y0, x1, y1;
};

Box BoundingBox(const Packing& p) {
  Box b{1e300, 1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < p.size(); ++i) {
    b.x0 = std::min(b.x0, p.x[i] - p.radius[i]);
    b.y0 = std::min(b.y0, p.y[i] - p.radius[i]);
    b.x1 = std::max(b.x1, p.x[i] + p.radius[i]);
    b.y1 = std::max(b.y1, p.y[i] + p.radius[i]);
  }
  return b;
}

// Walls touching the packing's bounding box: left, right, bottom, top (as the walls effect places
// them), or a subset.
std::vector<WallLine> BoxWalls(const Packing& p, bool sides, bool bottom, bool top) {
  const Box b = BoundingBox(p);
  std::vector<WallLine> walls;
  if (sides) {
    walls.push_back({b.x0, b.y0, 1.0, 0.0});
    walls.push_back({b.x1, b.y0, -1.0, 0.0});
  }
  if (bottom) walls.push_back({b.x0, b.y0, 0.0, 1.0});
  if (top) walls.push_back({b.x0, b.y1, 0.0, -1.0});
  return walls;
}

Result<DomainNetwork> DetectWithWalls(const Packing& p, const std::vector<WallLine>& lines,
                                      double max_gap) {
  SEEP_ASSIGN_OR_RETURN(const ContactList contacts, DetectContacts(p, max_gap));
  const WallContactList wall_contacts = FindWallContacts(p, lines, max_gap);
  const std::vector<DetectionWall> walls = ClipWalls(p, lines);
  DomainDetector detector;
  DomainNetwork net;
  SEEP_RETURN_IF_ERROR(detector.Detect(p, contacts, walls, wall_contacts, {max_gap}, &net));
  return net;
}

// A 3 x 3 square lattice in a closed box: 4 interior pores (2R x 2R), 8 wall pores (2R x R, two
// quarter sectors) and 4 corner pores (R x R, one quarter sector); every contact and every foot
// carries a pipe, every stretch of wall is a boundary pipe.
TEST(DomainWalls, SquareLatticeInAClosedBoxHasWallAndCornerPores) {
  const double R = 1.3e-3;
  const Result<Packing> lattice = SquareLattice(3, 3, R);
  ASSERT_TRUE(lattice.ok());
  const Result<DomainNetwork> net =
      DetectWithWalls(*lattice, BoxWalls(*lattice, true, true, true), 1e-9 * R);
  ASSERT_TRUE(net.ok()) << net.status().ToString();
  ASSERT_EQ(net->num_domains(), 16u);
  EXPECT_EQ(net->walls.num_vertices(), 12u + 4u);  // feet and corners
  EXPECT_EQ(net->num_pipes(), 12u + 12u);          // contacts and feet
  EXPECT_EQ(net->num_boundary_pipes(), 16u);       // stretches
  EXPECT_TRUE(testing::EulerHolds(*net));
  int interior = 0, wall = 0, corner = 0;
  const double tol = 1e-12 * R * R;
  for (std::size_t d = 0; d < net->num_domains(); ++d) {
    const double vd = net->apparent_volume[d];
    const double vp = net->pore_volume[d];
    if (std::abs(vd - 4 * R * R) < tol) {
      ++interior;
      EXPECT_NEAR(vp, (4 - kPi) * R * R, tol);
    } else if (std::abs(vd - 2 * R * R) < tol) {
      ++wall;
      EXPECT_NEAR(vp, (2 - kPi / 2) * R * R, tol);
    } else {
      ++corner;
      EXPECT_NEAR(vd, R * R, tol);
      EXPECT_NEAR(vp, (1 - kPi / 4) * R * R, tol);
    }
  }
  EXPECT_EQ(interior, 4);
  EXPECT_EQ(wall, 8);
  EXPECT_EQ(corner, 4);
  // The pores fill the box: sum V_d is its area, sum V_p its area less the disks.
  const double box = 36 * R * R;
  EXPECT_NEAR(testing::Sum(net->apparent_volume), box, 1e-12 * box);
  EXPECT_NEAR(testing::Sum(net->pore_volume), box - 9 * kPi * R * R, 1e-12 * box);
  for (std::size_t k = 0; k < net->num_boundary_pipes(); ++k) {
    EXPECT_TRUE(net->walls.IsWallEdge(net->boundary_pipe_contact[k]));
  }
}

// Only a floor: the wall pores along it are domains, the free ends of the floor are pruned and
// the other sides stay open (boundary pipes on particle contacts).
TEST(DomainWalls, AFloorAloneClosesThePoresAlongIt) {
  const double R = 0.7;
  const Result<Packing> lattice = SquareLattice(4, 3, R);
  ASSERT_TRUE(lattice.ok());
  const Result<DomainNetwork> net =
      DetectWithWalls(*lattice, BoxWalls(*lattice, false, true, false), 1e-9 * R);
  ASSERT_TRUE(net.ok()) << net.status().ToString();
  EXPECT_EQ(net->num_domains(), 6u + 3u);
  EXPECT_TRUE(testing::EulerHolds(*net));
  std::size_t stretches = 0, feet = 0;
  for (std::size_t k = 0; k < net->num_boundary_pipes(); ++k) {
    const std::int32_t c = net->boundary_pipe_contact[k];
    if (!net->walls.IsWallEdge(c)) continue;
    ++(net->walls.edge_particle[net->walls.Edge(c)] < 0 ? stretches : feet);
  }
  EXPECT_EQ(stretches, 3u);  // between the four feet; the two ends are pruned
  EXPECT_EQ(feet, 2u);       // the first and last foot edges face the open sides
  const double area = 6 * 4 * R * R + 3 * 2 * R * R;
  EXPECT_NEAR(testing::Sum(net->apparent_volume), area, 1e-12 * area);
}

// A disk pressed into the wall: its segment beyond the wall is not solid in the pores beside it.
TEST(DomainWalls, AnOverlapWithTheWallRemovesOnlyTheDiskInside) {
  const double R = 2e-3;
  const double overlap = 1e-2 * R;
  const Result<Packing> lattice = SquareLattice(3, 2, R);
  ASSERT_TRUE(lattice.ok());
  std::vector<WallLine> walls = BoxWalls(*lattice, true, true, true);
  walls[2].py += overlap;  // the floor pushed up into the bottom row
  const Result<DomainNetwork> net = DetectWithWalls(*lattice, walls, 1e-9 * R);
  ASSERT_TRUE(net.ok()) << net.status().ToString();
  const double box = (6 * R) * (4 * R - overlap);
  // Three disks lose a circular segment of height `overlap` beyond the floor.
  const double d = R - overlap;
  const double segment = R * R * std::acos(d / R) - d * std::sqrt(R * R - d * d);
  const double solid = 6 * kPi * R * R - 3 * segment;
  EXPECT_NEAR(testing::Sum(net->apparent_volume), box, 1e-12 * box);
  EXPECT_NEAR(testing::Sum(net->pore_volume), box - solid, 1e-11 * box);
}

// The positions of the wall vertices follow the particles and the walls.
TEST(DomainWalls, VertexPositionsFollowParticlesAndWalls) {
  const double R = 1.0;
  const Result<Packing> lattice = SquareLattice(2, 2, R);
  ASSERT_TRUE(lattice.ok());
  std::vector<WallLine> walls = BoxWalls(*lattice, true, true, true);
  const Result<DomainNetwork> net = DetectWithWalls(*lattice, walls, 1e-9);
  ASSERT_TRUE(net.ok());
  const DomainWalls& w = net->walls;
  std::vector<double> x(w.num_vertices()), y(w.num_vertices());
  WallVertexPositions(w, lattice->x, lattice->y, walls, x, y);
  for (std::size_t v = 0; v < w.num_vertices(); ++v) {
    EXPECT_DOUBLE_EQ(x[v], w.vertex_x[v]);
    EXPECT_DOUBLE_EQ(y[v], w.vertex_y[v]);
  }
  walls[3].py += 0.25;  // the top wall backs off
  std::vector<double> px = lattice->x;
  px[0] += 0.1;  // particle 0 slides along the floor
  WallVertexPositions(w, px, lattice->y, walls, x, y);
  for (std::size_t v = 0; v < w.num_vertices(); ++v) {
    if (w.vertex_particle[v] == 0 && w.vertex_wall[v] == 2) {
      EXPECT_DOUBLE_EQ(x[v], px[0]);
    }
    const bool top_corner =
        w.vertex_particle[v] < 0 && (w.vertex_wall[v] == 3 || w.vertex_other_wall[v] == 3);
    if (top_corner) {
      EXPECT_DOUBLE_EQ(y[v], walls[3].py);
    }
  }
}

TEST(DomainWalls, AWallContactOutOfOrderIsNamed) {
  const Result<Packing> lattice = SquareLattice(2, 2, 1.0);
  ASSERT_TRUE(lattice.ok());
  const std::vector<WallLine> lines = BoxWalls(*lattice, true, true, true);
  WallContactList wc = FindWallContacts(*lattice, lines, 1e-9);
  std::swap(wc.wall[0], wc.wall[1]);
  const Result<ContactList> contacts = DetectContacts(*lattice, 1e-9);
  ASSERT_TRUE(contacts.ok());
  DomainDetector detector;
  DomainNetwork net;
  const Status status =
      detector.Detect(*lattice, *contacts, ClipWalls(*lattice, lines), wc, {1e-9}, &net);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("wall contact 1"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace seep::core
