// Walls in the contact graph (docs/physics.md §2.4, option B): the pores between a wall and the
// particles against it become domains closed by the wall.
//
// A wall is a straight line with a unit normal pointing into the sample; the detection uses a
// segment of it, [begin, end] along the tangent t = (n_y, -n_x), so the sample lies on the left
// of the segment's direction (as on the left of every CCW domain loop). The graph gains "wall
// vertices", points of radius 0 appended after the particles:
//   - a foot: the projection of a particle's centre onto a wall it touches (a wall contact with
//     gap <= max_gap), joined to the particle by a "foot edge" (the particle-wall contact, which
//     carries a pipe between the two pores beside it, of length L = R + 0);
//   - the two ends of each segment; ends of different walls closer than a round-off tolerance are
//     one vertex, a corner where two walls meet.
// Consecutive vertices along a wall are joined by "stretch" edges (the wall itself): a stretch has
// the domain it closes on one side and the outside beyond the wall on the other, so it is a
// boundary pipe of the detection, and the scene decides whether fluid crosses it (a drained
// platen) or not. Ends no domain reaches (a wall longer than the sample) are pruned like any
// dangling chain. Radius 0 is what tells a wall vertex from a particle in the graph: its sector is
// empty, and a foot edge's overlap is the circular segment of the disk beyond the wall (half of it
// on each side of the foot edge), not a lens.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/status.h"

namespace seep::core {

// An infinite wall line: a point and the unit normal into the sample.
struct WallLine {
  double px = 0.0, py = 0.0;
  double nx = 0.0, ny = 1.0;
};

// The part of a wall line the detection uses: [begin, end] along t = (n_y, -n_x) from (px, py).
struct DetectionWall {
  WallLine line;
  double begin = 0.0;
  double end = 0.0;
};

// Particle-wall contacts, sorted by (particle, wall), with the surface gap (c - p).n - R.
struct WallContactList {
  std::vector<std::int32_t> particle;
  std::vector<std::int32_t> wall;
  std::vector<double> gap;

  std::size_t size() const { return particle.size(); }
  void Clear();
};

// Every (particle, wall) with gap <= max_gap and the centre on the sample side (gap > -R, the
// DEM's rule, DemContactForces::CollectFlowWallContacts), in
// (particle, wall) order: what a set-up without a DEM uses (a DEM lists its own).
WallContactList FindWallContacts(const Packing& packing, std::span<const WallLine> walls,
                                 double max_gap);

// The segments of the walls that bound the sample: each wall line clipped by the inside
// half-planes of the other walls (so walls meeting at a corner end there) and, where no other wall
// clips it, by the projection of the particles onto it widened by two of the largest radii. A wall
// whose line lies entirely outside another wall's half-plane bounds nothing and gets an empty
// segment (begin > end), which the detection skips.
std::vector<DetectionWall> ClipWalls(const Packing& packing, std::span<const WallLine> walls);

// The wall vertices and wall edges of a detection (DomainNetwork::walls). Vertex v has id
// num_particles + v in the loops; edge e has id num_contacts + e.
struct DomainWalls {
  // Loop ids from num_particles on are wall vertices, contact ids from num_contacts on wall
  // edges; without walls both stay at the largest id, so nothing is either.
  std::int32_t num_particles = std::numeric_limits<std::int32_t>::max();
  std::int32_t num_contacts = std::numeric_limits<std::int32_t>::max();
  // Per vertex: its wall, the second wall of a corner (-1 otherwise), the particle of a foot (-1
  // for an end or a corner), and its position at detection.
  std::vector<std::int32_t> vertex_wall, vertex_other_wall, vertex_particle;
  std::vector<double> vertex_x, vertex_y;
  // Per edge: its wall, the particle of a foot edge (-1 for a stretch), and the foot edge's gap
  // (its wall contact's) or the stretch's length. Its two ends are the detection contact's i, j.
  std::vector<std::int32_t> edge_wall, edge_particle;
  std::vector<double> edge_gap;

  std::size_t num_vertices() const { return vertex_wall.size(); }
  std::size_t num_edges() const { return edge_wall.size(); }
  bool empty() const { return vertex_wall.empty(); }
  bool IsWallVertex(std::int32_t id) const { return id >= num_particles; }
  bool IsWallEdge(std::int32_t contact) const { return contact >= num_contacts; }
  // The wall edge of a contact id (requires IsWallEdge).
  std::size_t Edge(std::int32_t contact) const {
    return static_cast<std::size_t>(contact - num_contacts);
  }
  void Clear();
  std::size_t MemoryBytes() const;
  // Field by field, doubles compared exactly.
  bool operator==(const DomainWalls&) const = default;
};

// Builds the augmented graph: `graph_packing` = the particles followed by the wall vertices
// (radius 0), `graph_contacts` = the contacts followed by the wall edges (not in (i, j) order;
// the detection does not need it past its input check). The wall contacts must be sorted by
// (particle, wall), name valid ids and have gap <= max_gap; a foot outside its wall's segment is
// clamped onto it. InvalidArgument naming the wall contact otherwise.
Status BuildWallGraph(const Packing& packing, const ContactList& contacts,
                      std::span<const DetectionWall> walls, const WallContactList& wall_contacts,
                      DomainWalls* out, Packing* graph_packing, ContactList* graph_contacts);

// The current positions of the wall vertices: feet at the projection of their particle's current
// centre onto their wall's current line, corners at the intersection of their two lines, free
// ends where they were detected. x, y (particle positions) are indexed by particle id.
void WallVertexPositions(const DomainWalls& walls, std::span<const double> x,
                         std::span<const double> y, std::span<const WallLine> lines,
                         std::span<double> vertex_x, std::span<double> vertex_y);

}  // namespace seep::core
