#include "platen_permeameter.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/steady_state_solver.h"

namespace seep::core::effects_internal {
namespace {

bool OnX(WallSide side) { return side == WallSide::kLeft || side == WallSide::kRight; }

// The index of the side wall on `side`, if exactly one.
std::optional<std::size_t> SideWallIndex(const WallsEffectSpec& walls, WallSide side) {
  std::optional<std::size_t> found;
  for (std::size_t w = 0; w < walls.walls.size(); ++w) {
    if (walls.walls[w].segment || walls.walls[w].side != side) continue;
    if (found) return std::nullopt;
    found = w;
  }
  return found;
}

}  // namespace

std::optional<PlatenPair> FindPlatenPair(const SceneSpec& scene) {
  const auto* walls = FindEffect<WallsEffectSpec>(scene);
  if (walls == nullptr || !HasFlow(scene)) return std::nullopt;
  std::optional<PlatenPair> out;
  for (const auto& [a_side, b_side] : {std::pair{WallSide::kLeft, WallSide::kRight},
                                       std::pair{WallSide::kBottom, WallSide::kTop}}) {
    const auto a = SideWallIndex(*walls, a_side);
    const auto b = SideWallIndex(*walls, b_side);
    if (!a || !b) continue;
    const auto& da = walls->walls[*a].drain;
    const auto& db = walls->walls[*b].drain;
    if (!da || !db || da->pressure_pa == db->pressure_pa) continue;
    if (out) return std::nullopt;  // two pairs: which axis would be meant is not clear
    const bool a_high = da->pressure_pa > db->pressure_pa;
    out = PlatenPair{a_high ? *a : *b, a_high ? *b : *a, OnX(a_side)};
  }
  return out;
}

double PlatenPermeability(const LiveState& s, const PlatenPair& pair) {
  const auto& walls = FindEffect<WallsEffectSpec>(*s.scene)->walls;
  const double dp = walls[pair.high].drain->pressure_pa - walls[pair.low].drain->pressure_pa;
  const std::int32_t high = pair.high < s.net.wall_node.size() ? s.net.wall_node[pair.high] : -1;
  const std::int32_t low = pair.low < s.net.wall_node.size() ? s.net.wall_node[pair.low] : -1;
  if (dp == 0.0 || high < 0 || low < 0 || s.walls.size() <= std::max(pair.high, pair.low)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // The steady flow of the network as it is now, solved on a copy: the transient flux at the
  // platens of a sample that deforms carries the fluid its pores pump in and out, which at a
  // laboratory shear rate of a DEM test can be tens of times the seepage itself.
  FlowNetwork probe = s.net.flow;
  for (std::size_t d = 0; d < probe.num_domains(); ++d) {
    if (probe.source_rate()[d] != 0.0) {
      if (!probe.SetSource(static_cast<std::int32_t>(d), 0.0).ok()) {
        return std::numeric_limits<double>::quiet_NaN();
      }
    }
  }
  if (!SolveSteadyState(probe).ok()) return std::numeric_limits<double>::quiet_NaN();
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(probe);
  const double q = 0.5 * (NodeInflow(fluxes, high) - NodeInflow(fluxes, low));
  const auto coordinate = [&](std::size_t w) {
    return pair.along_x ? s.walls[w].px : s.walls[w].py;
  };
  const double length = std::abs(coordinate(pair.high) - coordinate(pair.low));
  // Across: between the other pair of side walls when the scene has both, else the particles.
  const auto* spec = FindEffect<WallsEffectSpec>(*s.scene);
  const WallSide lo_side = pair.along_x ? WallSide::kBottom : WallSide::kLeft;
  const WallSide hi_side = pair.along_x ? WallSide::kTop : WallSide::kRight;
  double width = 0.0;
  const auto lo = SideWallIndex(*spec, lo_side);
  const auto hi = SideWallIndex(*spec, hi_side);
  if (lo && hi) {
    width = pair.along_x ? s.walls[*hi].py - s.walls[*lo].py : s.walls[*hi].px - s.walls[*lo].px;
  } else {
    double min = std::numeric_limits<double>::infinity(), max = -min;
    const bool moving = s.moves();
    const std::size_t n = moving ? s.particles.size() : s.net.packing.size();
    for (std::size_t i = 0; i < n; ++i) {
      const double c = moving ? (pair.along_x ? s.particles.y[i] : s.particles.x[i])
                              : (pair.along_x ? s.net.packing.y[i] : s.net.packing.x[i]);
      const double r = moving ? s.particles.radius[i] : s.net.packing.radius[i];
      min = std::min(min, c - r);
      max = std::max(max, c + r);
    }
    width = max - min;
  }
  return s.scene->fluid.viscosity_pa_s * q * length / (std::abs(width) * dp);
}

}  // namespace seep::core::effects_internal
