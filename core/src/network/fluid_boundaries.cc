#include "seep/core/network/fluid_boundaries.h"

#include <fmt/format.h>

#include <algorithm>

namespace seep::core {
namespace {

// The drained walls of the scene, by their index in the walls effect.
std::vector<std::size_t> DrainedWalls(const SceneSpec& scene) {
  std::vector<std::size_t> out;
  if (const auto* walls = FindEffect<WallsEffectSpec>(scene)) {
    for (std::size_t w = 0; w < walls->walls.size(); ++w) {
      if (walls->walls[w].drain) out.push_back(w);
    }
  }
  return out;
}

std::size_t ReservoirCount(const SceneSpec& scene) {
  return scene.boundary.walls_only ? 0 : 2;  // inlet/outlet or well/outer
}

bool IsPressureRegion(const BoundaryRegionSpec& region) {
  return std::holds_alternative<FixedPressure>(region.condition);
}

}  // namespace

std::vector<std::string> FluidBoundaryNames(const SceneSpec& scene) {
  std::vector<std::string> names;
  if (!scene.boundary.walls_only) {
    if (scene.boundary.radial) {
      names = {"well", "outer"};
    } else {
      names = {"inlet", "outlet"};
    }
  }
  const auto* walls = FindEffect<WallsEffectSpec>(scene);
  const std::vector<std::size_t> drained = DrainedWalls(scene);
  for (const std::size_t w : drained) {
    const WallSide side = walls->walls[w].side;
    const auto same_side = std::count_if(drained.begin(), drained.end(), [&](std::size_t v) {
      return walls->walls[v].side == side;
    });
    names.push_back(same_side > 1 ? fmt::format("{}_wall_{}", WallSideName(side), w)
                                  : fmt::format("{}_wall", WallSideName(side)));
  }
  for (const BoundaryRegionSpec& region : scene.boundary.regions) {
    if (IsPressureRegion(region)) names.push_back("region_" + region.name);
  }
  return names;
}

Result<std::vector<std::int32_t>> FluidBoundaryOfNodes(const SceneSpec& scene,
                                                       const SceneNetwork& net) {
  const std::size_t n = net.flow.num_domains();
  std::vector<std::int32_t> of(n, -1);
  const auto mark = [&of, n](std::int32_t node, std::int32_t boundary) {
    if (node >= 0 && static_cast<std::size_t>(node) < n)
      of[static_cast<std::size_t>(node)] = boundary;
  };
  if (ReservoirCount(scene) == 2) {
    if (scene.boundary.radial) {
      mark(net.well_domain, 0);
      mark(net.outer_node, 1);
    } else {
      mark(net.inlet_node, 0);
      mark(net.outlet_node, 1);
    }
  }
  const std::vector<std::size_t> drained = DrainedWalls(scene);
  for (std::size_t k = 0; k < drained.size(); ++k) {
    if (drained[k] < net.wall_node.size()) {
      mark(net.wall_node[drained[k]], static_cast<std::int32_t>(ReservoirCount(scene) + k));
    }
  }
  // Each pressure region is one boundary however many domains it holds (the books add them up).
  auto boundary = static_cast<std::int32_t>(ReservoirCount(scene) + drained.size());
  const auto& regions = scene.boundary.regions;
  for (std::size_t r = 0; r < regions.size() && r < net.regions.size(); ++r) {
    if (!IsPressureRegion(regions[r])) continue;
    for (const std::int32_t d : net.regions[r].nodes) mark(d, boundary);
    ++boundary;
  }
  const auto role = net.flow.role();
  for (std::size_t d = 0; d < n; ++d) {
    if (role[d] != DomainRole::kFixedPressure) {
      of[d] = -1;  // an injected well is a source: its fluid is the sample's
    } else if (of[d] < 0) {
      return Internal(
          fmt::format("fluid books: fixed-pressure node {} is none of the scene's boundaries", d));
    }
  }
  return of;
}

}  // namespace seep::core
