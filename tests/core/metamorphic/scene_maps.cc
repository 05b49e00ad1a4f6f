#include "scene_maps.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "seep/core/network/scene_network.h"

namespace seep::core::metamorphic {
namespace {

// Whether the map takes the low end of `axis` to the high end of the image's axis.
bool FlipsAxis(FlowAxis axis, Turn turn) {
  switch (turn) {
    case Turn::kNone:
      return false;
    case Turn::kQuarter:
      return axis == FlowAxis::kY;  // low y goes to high x
    case Turn::kMirrorX:
      return axis == FlowAxis::kX;
  }
  return false;
}

FlowAxis MapAxis(FlowAxis axis, Turn turn) {
  if (turn != Turn::kQuarter) return axis;
  return axis == FlowAxis::kX ? FlowAxis::kY : FlowAxis::kX;
}

RegionShape MapShape(const RegionShape& shape, const SceneMap& map) {
  if (const auto* box = std::get_if<BoxShape>(&shape)) {
    double ax, ay, bx, by;
    map.Point(box->x0, box->y0, &ax, &ay);
    map.Point(box->x1, box->y1, &bx, &by);
    return BoxShape{std::min(ax, bx), std::min(ay, by), std::max(ax, bx), std::max(ay, by)};
  }
  if (const auto* circle = std::get_if<CircleShape>(&shape)) {
    CircleShape out = *circle;
    map.Point(circle->cx, circle->cy, &out.cx, &out.cy);
    return out;
  }
  if (const auto* half = std::get_if<HalfPlaneShape>(&shape)) {
    HalfPlaneShape out;
    map.Point(half->px, half->py, &out.px, &out.py);
    map.Vector(half->nx, half->ny, &out.nx, &out.ny);
    return out;
  }
  const auto& polygon = std::get<PolygonShape>(shape);
  PolygonShape out = polygon;
  for (std::size_t k = 0; k < polygon.x.size(); ++k) {
    map.Point(polygon.x[k], polygon.y[k], &out.x[k], &out.y[k]);
  }
  return out;
}

}  // namespace

double SnapToGrid(double v) { return std::round(v / kGrid) * kGrid; }

namespace {

// A number in [-1, 1) from k alone (SplitMix64): the same jitter for a particle in every map.
double UnitNoise(std::uint64_t k) {
  std::uint64_t z = k + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-52 - 1.0;
}

}  // namespace

void SceneMap::Vector(double x, double y, double* ox, double* oy) const {
  *ox = turn == Turn::kQuarter ? -y : turn == Turn::kMirrorX ? -x : x;
  *oy = turn == Turn::kQuarter ? x : y;
}

void SceneMap::Point(double x, double y, double* ox, double* oy) const {
  Vector(x, y, ox, oy);
  *ox += tx;
  *oy += ty;
}

std::string SceneMap::Name() const {
  const char* turn_name = turn == Turn::kNone      ? "translation"
                          : turn == Turn::kQuarter ? "quarter turn"
                                                   : "mirror";
  return fmt::format("{} + ({}, {}) m", turn_name, tx, ty);
}

WallSide MapSide(WallSide side, Turn turn) {
  if (turn == Turn::kQuarter) {
    switch (side) {
      case WallSide::kBottom:
        return WallSide::kRight;
      case WallSide::kRight:
        return WallSide::kTop;
      case WallSide::kTop:
        return WallSide::kLeft;
      case WallSide::kLeft:
        return WallSide::kBottom;
    }
  }
  if (turn == Turn::kMirrorX) {
    if (side == WallSide::kLeft) return WallSide::kRight;
    if (side == WallSide::kRight) return WallSide::kLeft;
  }
  return side;
}

SceneSpec MaterialisedScene(const SceneSpec& scene) { return *MapScene(scene, SceneMap{}).scene; }

MappedScene MapScene(const SceneSpec& scene, const SceneMap& map) {
  Result<Packing> packing = BuildScenePacking(scene.packing);
  if (!packing.ok()) return {std::nullopt, "packing: " + packing.status().message()};
  SceneSpec out = scene;
  ParticleListSpec list;
  list.x_m.resize(packing->size());
  list.y_m.resize(packing->size());
  list.radius_m = packing->radius;
  for (std::size_t i = 0; i < packing->size(); ++i) {
    const double jitter = kJitter * packing->radius[i];
    map.Point(SnapToGrid(packing->x[i] + jitter * UnitNoise(2 * i)),
              SnapToGrid(packing->y[i] + jitter * UnitNoise(2 * i + 1)), &list.x_m[i],
              &list.y_m[i]);
  }
  out.packing.source = std::move(list);

  BoundarySpec& b = out.boundary;
  map.Point(scene.boundary.initial_pressure_x_m, scene.boundary.initial_pressure_y_m,
            &b.initial_pressure_x_m, &b.initial_pressure_y_m);
  const bool linear = !b.radial && !b.walls_only;
  if (linear && FlipsAxis(b.axis, map.turn)) {
    if (b.closed_inlet) {
      return {std::nullopt, "a closed inlet would move to the outlet's end"};
    }
    std::swap(b.inlet_pressure_pa, b.outlet_pressure_pa);
    for (StageSpec& stage : out.stages)
      std::swap(stage.inlet_pressure_pa, stage.outlet_pressure_pa);
  }
  if (linear) b.axis = MapAxis(b.axis, map.turn);
  for (BoundaryRegionSpec& region : b.regions) region.shape = MapShape(region.shape, map);

  for (EffectSpec& e : out.effects) {
    if (auto* gravity = std::get_if<GravityEffectSpec>(&e)) {
      const GravityEffectSpec g = *gravity;
      map.Vector(g.gx_m_s2, g.gy_m_s2, &gravity->gx_m_s2, &gravity->gy_m_s2);
    }
    if (auto* walls = std::get_if<WallsEffectSpec>(&e)) {
      for (WallSpec& wall : walls->walls) {
        wall.side = MapSide(wall.side, map.turn);
        if (!wall.segment) continue;
        WallSegmentSpec& s = *wall.segment;
        const WallSegmentSpec before = s;
        map.Point(before.x0_m, before.y0_m, &s.x0_m, &s.y0_m);
        map.Point(before.x1_m, before.y1_m, &s.x1_m, &s.y1_m);
        // A mirror reverses the side the normal is on (the left of the direction of travel).
        if (map.turn == Turn::kMirrorX) {
          std::swap(s.x0_m, s.x1_m);
          std::swap(s.y0_m, s.y1_m);
        }
      }
    }
  }
  return {std::move(out), ""};
}

}  // namespace seep::core::metamorphic
