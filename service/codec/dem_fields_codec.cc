// Bonds and wall segments of GetJobFields (see dem_fields_codec.h).
#include "codec/dem_fields_codec.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include "seep/core/network/scene_walls.h"

namespace seep::service {
namespace {

using core::WallLine;

// An interval [lo, hi] of the parameter s along a line p + s t.
struct Interval {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool empty() const { return !(lo <= hi); }
};

// Keeps the s with a + s b >= 0. A parallel constraint (b = 0) is ignored: a wall outside
// another's side still gets drawn, and a box edge parallel to the line never cuts it.
void KeepNonNegative(double a, double b, Interval* s) {
  if (std::abs(b) < 1e-12) return;
  const double root = -a / b;
  if (b > 0.0) {
    s->lo = std::max(s->lo, root);
  } else {
    s->hi = std::min(s->hi, root);
  }
}

struct Box {
  double x_min, y_min, x_max, y_max;
};

// The disks' bounding box widened by two largest diameters on every side, so that a wall
// touching the outermost disks lies well inside it; the unit square around the origin without
// particles.
Box DrawingBox(const core::ParticleView& p) {
  if (p.size() == 0) return {-1.0, -1.0, 1.0, 1.0};
  Box box{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  double r_max = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    box.x_min = std::min(box.x_min, p.x[k] - p.radius[k]);
    box.y_min = std::min(box.y_min, p.y[k] - p.radius[k]);
    box.x_max = std::max(box.x_max, p.x[k] + p.radius[k]);
    box.y_max = std::max(box.y_max, p.y[k] + p.radius[k]);
    r_max = std::max(r_max, p.radius[k]);
  }
  const double margin = 4.0 * r_max;
  return {box.x_min - margin, box.y_min - margin, box.x_max + margin, box.y_max + margin};
}

// The part of wall w's line inside the box and on the inner side of every other wall; the part
// inside the box alone when the walls leave nothing; the box's diagonal centred on the foot of
// its centre when the line misses the box.
std::pair<double, double> SegmentParameters(const std::vector<WallLine>& lines, std::size_t w,
                                            const Box& box) {
  const WallLine& line = lines[w];
  const double tx = line.ny;
  const double ty = -line.nx;
  Interval in_box;
  KeepNonNegative(line.px - box.x_min, tx, &in_box);
  KeepNonNegative(box.x_max - line.px, -tx, &in_box);
  KeepNonNegative(line.py - box.y_min, ty, &in_box);
  KeepNonNegative(box.y_max - line.py, -ty, &in_box);
  Interval inside = in_box;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    if (k == w) continue;
    const WallLine& other = lines[k];
    KeepNonNegative((line.px - other.px) * other.nx + (line.py - other.py) * other.ny,
                    tx * other.nx + ty * other.ny, &inside);
  }
  if (!inside.empty()) return {inside.lo, inside.hi};
  if (!in_box.empty()) return {in_box.lo, in_box.hi};
  const double cx = 0.5 * (box.x_min + box.x_max);
  const double cy = 0.5 * (box.y_min + box.y_max);
  const double foot = (cx - line.px) * tx + (cy - line.py) * ty;
  const double half = 0.5 * std::hypot(box.x_max - box.x_min, box.y_max - box.y_min);
  return {foot - half, foot + half};
}

void AddWallSegments(const core::Simulation& sim, v1::JobFields* out) {
  // The DEM's walls where the particles move (their current positions), else the fluid's.
  const std::vector<core::DemWall>& dem_walls = sim.stepper().state().walls;
  const std::vector<WallLine> lines =
      dem_walls.empty() ? sim.network().walls : core::WallLines(dem_walls);
  const Box box = DrawingBox(sim.particles());
  const auto& contacts = sim.stepper().state().contacts;
  for (std::size_t w = 0; w < lines.size(); ++w) {
    // A segment wall is drawn as itself, a line clipped to the drawing.
    const bool segment = !dem_walls.empty() && contacts.has_value() &&
                         w < contacts->wall_extents().size() &&
                         contacts->wall_extents()[w].finite();
    const auto [s0, s1] =
        segment ? std::pair{contacts->wall_extents()[w].lo, contacts->wall_extents()[w].hi}
                : SegmentParameters(lines, w, box);
    const WallLine& line = lines[w];
    out->add_wall_x0_m(line.px + s0 * line.ny);
    out->add_wall_y0_m(line.py - s0 * line.nx);
    out->add_wall_x1_m(line.px + s1 * line.ny);
    out->add_wall_y1_m(line.py - s1 * line.nx);
  }
}

}  // namespace

BondList CurrentBonds(const core::Simulation& sim) {
  BondList bonds;
  const auto& contacts = sim.stepper().state().contacts;
  if (!contacts.has_value()) return bonds;
  core::DemContactState state = contacts->SaveState();
  bonds.i = std::move(state.bond_i);
  bonds.j = std::move(state.bond_j);
  bonds.intact.resize(bonds.i.size());
  for (std::size_t b = 0; b < bonds.i.size(); ++b) {
    bonds.intact[b] = state.bond_failure[b] == static_cast<std::uint8_t>(core::BondFailure::kNone);
  }
  return bonds;
}

void DemFieldsToProto(const core::Simulation& sim, const BondList& at_set_up, v1::JobFields* out) {
  const BondList now = CurrentBonds(sim);
  // Both lists are sorted by (i, j): one merge finds each set-up bond's state now.
  std::size_t k = 0;
  for (std::size_t b = 0; b < at_set_up.i.size(); ++b) {
    const std::pair<std::int32_t, std::int32_t> key{at_set_up.i[b], at_set_up.j[b]};
    while (k < now.i.size() && std::pair{now.i[k], now.j[k]} < key) ++k;
    const bool intact =
        k < now.i.size() && std::pair{now.i[k], now.j[k]} == key && now.intact[k] != 0;
    out->add_bond_particle_i(key.first);
    out->add_bond_particle_j(key.second);
    out->add_bond_broken(!intact);
  }
  AddWallSegments(sim, out);
}

}  // namespace seep::service
