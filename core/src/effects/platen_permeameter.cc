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
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const WallsEffectSpec& spec = *FindEffect<WallsEffectSpec>(*s.scene);
  const double dp =
      spec.walls[pair.high].drain->pressure_pa - spec.walls[pair.low].drain->pressure_pa;
  const std::int32_t high = pair.high < s.net.wall_node.size() ? s.net.wall_node[pair.high] : -1;
  const std::int32_t low = pair.low < s.net.wall_node.size() ? s.net.wall_node[pair.low] : -1;
  if (high < 0 || low < 0 || s.walls.size() <= std::max(pair.high, pair.low)) return kNaN;
  // The steady flow of the network as it is now, solved on a copy: the transient flux at the
  // platens of a sample that deforms carries the fluid its pores pump in and out, which at a
  // laboratory shear rate of a DEM test can be tens of times the seepage itself.
  FlowNetwork probe = s.net.flow;
  for (std::size_t d = 0; d < probe.num_domains(); ++d) {
    if (probe.source_rate()[d] != 0.0 && !probe.SetSource(static_cast<std::int32_t>(d), 0.0).ok()) {
      return kNaN;
    }
  }
  SteadyStateOptions steady;
  steady.linear_solver = s.scene->solver.linear_solver;
  if (!SolveSteadyState(probe, steady).ok()) return kNaN;
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(probe);
  const double q = 0.5 * (NodeInflow(fluxes, high) - NodeInflow(fluxes, low));
  const auto along = [&](const DemWall& w) { return pair.along_x ? w.px : w.py; };
  const auto across = [&](const DemWall& w) { return pair.along_x ? w.py : w.px; };
  const double length = std::abs(along(s.walls[pair.high]) - along(s.walls[pair.low]));
  // Across: between the other pair of side walls when the scene has both, else the particles
  // (walls need the contacts effect, so the particles are the DEM's).
  const auto lo = SideWallIndex(spec, pair.along_x ? WallSide::kBottom : WallSide::kLeft);
  const auto hi = SideWallIndex(spec, pair.along_x ? WallSide::kTop : WallSide::kRight);
  double width = 0.0;
  if (lo && hi) {
    width = std::abs(across(s.walls[*hi]) - across(s.walls[*lo]));
  } else {
    const DemParticles& p = s.particles;
    double min = std::numeric_limits<double>::infinity(), max = -min;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const double c = pair.along_x ? p.y[i] : p.x[i];
      min = std::min(min, c - p.radius[i]);
      max = std::max(max, c + p.radius[i]);
    }
    width = max - min;
  }
  const Result<double> k = DarcyPermeability(s.scene->fluid.viscosity_pa_s, q, length, width, dp);
  return k.ok() ? *k : kNaN;
}

}  // namespace seep::core::effects_internal
