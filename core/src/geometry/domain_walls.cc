// Wall vertices and wall edges of the contact graph (see domain_walls.h).
#include "seep/core/geometry/domain_walls.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "../sizes.h"

namespace seep::core {
namespace {

// Signed distance of a point from the wall line (positive on the sample side).
double Height(const WallLine& w, double x, double y) {
  return (x - w.px) * w.nx + (y - w.py) * w.ny;
}

// Coordinate of a point along the wall's tangent t = (n_y, -n_x).
double Along(const WallLine& w, double x, double y) {
  return (x - w.px) * w.ny - (y - w.py) * w.nx;
}

// The corner of two wall lines: n_a . q = n_a . p_a and n_b . q = n_b . p_b (Cramer's rule).
void Corner(const WallLine& a, const WallLine& b, double* x, double* y) {
  const double ca = a.nx * a.px + a.ny * a.py;
  const double cb = b.nx * b.px + b.ny * b.py;
  const double det = a.nx * b.ny - a.ny * b.nx;
  *x = (ca * b.ny - cb * a.ny) / det;
  *y = (a.nx * cb - b.nx * ca) / det;
}

struct Foot {
  double along;  // clamped onto the segment
  bool clamped;
  std::int32_t particle;
  double gap;
};

}  // namespace

void WallContactList::Clear() {
  particle.clear();
  wall.clear();
  gap.clear();
}

void DomainWalls::Clear() {
  num_particles = num_contacts = std::numeric_limits<std::int32_t>::max();
  vertex_wall.clear();
  vertex_other_wall.clear();
  vertex_particle.clear();
  vertex_x.clear();
  vertex_y.clear();
  edge_wall.clear();
  edge_particle.clear();
  edge_gap.clear();
}

std::size_t DomainWalls::MemoryBytes() const {
  return internal::VectorBytes(vertex_wall, vertex_other_wall, vertex_particle, vertex_x, vertex_y,
                               edge_wall, edge_particle, edge_gap);
}

WallContactList FindWallContacts(const Packing& packing, std::span<const WallLine> walls,
                                 double max_gap) {
  WallContactList out;
  for (std::size_t i = 0; i < packing.size(); ++i) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
      const double height = Height(walls[w], packing.x[i], packing.y[i]);
      const double gap = height - packing.radius[i];
      if (!(gap <= max_gap) || !(gap > -packing.radius[i])) continue;
      out.particle.push_back(static_cast<std::int32_t>(i));
      out.wall.push_back(static_cast<std::int32_t>(w));
      out.gap.push_back(gap);
    }
  }
  return out;
}

std::vector<DetectionWall> ClipWalls(const Packing& packing, std::span<const WallLine> walls) {
  double max_radius = 0.0;
  for (double r : packing.radius) max_radius = std::max(max_radius, r);
  std::vector<DetectionWall> out;
  out.reserve(walls.size());
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const WallLine& line = walls[w];
    DetectionWall segment{line, std::numeric_limits<double>::infinity(),
                          -std::numeric_limits<double>::infinity()};
    // Where no other wall clips the line: the particles' shadow on it, widened.
    for (std::size_t i = 0; i < packing.size(); ++i) {
      const double u = Along(line, packing.x[i], packing.y[i]);
      segment.begin = std::min(segment.begin, u - 2.0 * max_radius);
      segment.end = std::max(segment.end, u + 2.0 * max_radius);
    }
    // Each other wall keeps the part of this line on its sample side: h(u) = h0 + u (t . n_k).
    const double tx = line.ny;
    const double ty = -line.nx;
    for (std::size_t k = 0; k < walls.size(); ++k) {
      if (k == w) continue;
      const WallLine& other = walls[k];
      const double h0 = Height(other, line.px, line.py);
      const double slope = tx * other.nx + ty * other.ny;
      if (slope > 0.0) {
        segment.begin = std::max(segment.begin, -h0 / slope);
      } else if (slope < 0.0) {
        segment.end = std::min(segment.end, -h0 / slope);
      } else if (h0 < 0.0) {
        segment.end = -std::numeric_limits<double>::infinity();  // parallel and outside
      }
    }
    out.push_back(segment);
  }
  return out;
}

Status BuildWallGraph(const Packing& packing, const ContactList& contacts,
                      std::span<const DetectionWall> walls, const WallContactList& wall_contacts,
                      DomainWalls* out, Packing* graph_packing, ContactList* graph_contacts) {
  const std::size_t n = packing.size();
  const std::size_t nw = wall_contacts.size();
  if (wall_contacts.wall.size() != nw || wall_contacts.gap.size() != nw) {
    return InvalidArgument("domain detection: wall contact arrays differ in length");
  }
  for (std::size_t k = 0; k < nw; ++k) {
    const std::int32_t p = wall_contacts.particle[k];
    const std::int32_t w = wall_contacts.wall[k];
    const bool ids_ok = p >= 0 && static_cast<std::size_t>(p) < n && w >= 0 &&
                        static_cast<std::size_t>(w) < walls.size();
    const bool order_ok = k == 0 || wall_contacts.particle[k - 1] < p ||
                          (wall_contacts.particle[k - 1] == p && wall_contacts.wall[k - 1] < w);
    if (!ids_ok || !order_ok || !std::isfinite(wall_contacts.gap[k])) {
      return InvalidArgument("domain detection: wall contact " + std::to_string(k) + " (particle " +
                             std::to_string(p) + ", wall " + std::to_string(w) +
                             ") must name a particle below " + std::to_string(n) +
                             " and a wall below " + std::to_string(walls.size()) +
                             ", have a finite gap and follow its predecessor in (particle, wall) "
                             "order");
    }
  }

  DomainWalls& dw = *out;
  dw.Clear();
  dw.num_particles = static_cast<std::int32_t>(n);
  dw.num_contacts = static_cast<std::int32_t>(contacts.size());
  *graph_packing = packing;
  *graph_contacts = contacts;

  // Corner tolerance: round-off of two line intersections computed from either wall.
  double extent = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    extent = std::max({extent, std::abs(packing.x[i]), std::abs(packing.y[i]), packing.radius[i]});
  }
  const double tolerance = 1e-9 * extent;

  auto add_vertex = [&](std::int32_t wall, std::int32_t particle, double x, double y) {
    dw.vertex_wall.push_back(wall);
    dw.vertex_other_wall.push_back(-1);
    dw.vertex_particle.push_back(particle);
    dw.vertex_x.push_back(x);
    dw.vertex_y.push_back(y);
    graph_packing->Add(x, y, 0.0);
    return static_cast<std::int32_t>(n + dw.vertex_wall.size() - 1);
  };
  // An end at (x, y): the end of an earlier wall there (a corner), or a new vertex.
  auto end_vertex = [&](std::int32_t wall, double x, double y) {
    for (std::size_t v = 0; v < dw.num_vertices(); ++v) {
      if (dw.vertex_particle[v] >= 0 || dw.vertex_other_wall[v] >= 0) continue;
      if (std::abs(dw.vertex_x[v] - x) <= tolerance && std::abs(dw.vertex_y[v] - y) <= tolerance) {
        dw.vertex_other_wall[v] = wall;
        return static_cast<std::int32_t>(n + v);
      }
    }
    return add_vertex(wall, -1, x, y);
  };
  auto add_edge = [&](std::int32_t wall, std::int32_t particle, std::int32_t a, std::int32_t b,
                      double gap) {
    dw.edge_wall.push_back(wall);
    dw.edge_particle.push_back(particle);
    dw.edge_gap.push_back(gap);
    graph_contacts->i.push_back(std::min(a, b));
    graph_contacts->j.push_back(std::max(a, b));
    graph_contacts->gap.push_back(gap);
  };

  std::vector<Foot> feet;
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const DetectionWall& segment = walls[w];
    if (!(segment.begin <= segment.end)) continue;
    const WallLine& line = segment.line;
    const auto wall = static_cast<std::int32_t>(w);
    feet.clear();
    for (std::size_t k = 0; k < nw; ++k) {
      if (wall_contacts.wall[k] != wall) continue;
      const auto p = static_cast<std::size_t>(wall_contacts.particle[k]);
      const double along = Along(line, packing.x[p], packing.y[p]);
      const double clamped = std::clamp(along, segment.begin, segment.end);
      feet.push_back({clamped, clamped != along, wall_contacts.particle[k], wall_contacts.gap[k]});
    }
    std::sort(feet.begin(), feet.end(), [](const Foot& a, const Foot& b) {
      return a.along < b.along || (a.along == b.along && a.particle < b.particle);
    });
    const auto point = [&](double along, double* x, double* y) {
      *x = line.px + along * line.ny;
      *y = line.py - along * line.nx;
    };
    double x = 0.0, y = 0.0;
    point(segment.begin, &x, &y);
    std::int32_t previous = end_vertex(wall, x, y);
    double previous_along = segment.begin;
    for (const Foot& foot : feet) {
      if (foot.clamped) {
        point(foot.along, &x, &y);
      } else {  // WallVertexPositions' formula, so the detection positions reproduce it exactly
        const auto p = static_cast<std::size_t>(foot.particle);
        const double height = Height(line, packing.x[p], packing.y[p]);
        x = packing.x[p] - height * line.nx;
        y = packing.y[p] - height * line.ny;
      }
      const std::int32_t vertex = add_vertex(wall, foot.particle, x, y);
      add_edge(wall, foot.particle, foot.particle, vertex, foot.gap);
      add_edge(wall, -1, previous, vertex, foot.along - previous_along);
      previous = vertex;
      previous_along = foot.along;
    }
    point(segment.end, &x, &y);
    add_edge(wall, -1, previous, end_vertex(wall, x, y), segment.end - previous_along);
  }
  // Corners where WallVertexPositions puts them, so the detected positions reproduce it exactly.
  for (std::size_t v = 0; v < dw.num_vertices(); ++v) {
    if (dw.vertex_other_wall[v] < 0) continue;
    Corner(walls[static_cast<std::size_t>(dw.vertex_wall[v])].line,
           walls[static_cast<std::size_t>(dw.vertex_other_wall[v])].line, &dw.vertex_x[v],
           &dw.vertex_y[v]);
    graph_packing->x[n + v] = dw.vertex_x[v];
    graph_packing->y[n + v] = dw.vertex_y[v];
  }
  return Status::Ok();
}

void WallVertexPositions(const DomainWalls& walls, std::span<const double> x,
                         std::span<const double> y, std::span<const WallLine> lines,
                         std::span<double> vertex_x, std::span<double> vertex_y) {
  for (std::size_t v = 0; v < walls.num_vertices(); ++v) {
    const WallLine& a = lines[static_cast<std::size_t>(walls.vertex_wall[v])];
    const std::int32_t particle = walls.vertex_particle[v];
    if (particle >= 0) {
      const auto p = static_cast<std::size_t>(particle);
      const double height = Height(a, x[p], y[p]);
      vertex_x[v] = x[p] - height * a.nx;
      vertex_y[v] = y[p] - height * a.ny;
      continue;
    }
    const std::int32_t other = walls.vertex_other_wall[v];
    if (other < 0) {
      vertex_x[v] = walls.vertex_x[v];
      vertex_y[v] = walls.vertex_y[v];
      continue;
    }
    Corner(a, lines[static_cast<std::size_t>(other)], &vertex_x[v], &vertex_y[v]);
  }
}

}  // namespace seep::core
