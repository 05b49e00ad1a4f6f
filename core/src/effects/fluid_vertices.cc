#include "seep/core/effects/fluid_vertices.h"

#include <algorithm>

#include "../parallel_threshold.h"
#include "seep/core/effects/live_state.h"

namespace seep::core {

ParticleView FluidVertices::Current(const LiveState& s) {
  return Fill(s, s.particles.x, s.particles.y, false);
}

ParticleView FluidVertices::CurrentInStep(const LiveState& s) {
  const DomainWalls& walls = s.net.domains.walls;
  if (walls.empty()) return ParticleView{s.particles.x, s.particles.y, s.particles.radius};
  if (s.step_stamp != 0 && s.step_stamp == filled_stamp_ &&
      s.topology_version == filled_topology_ &&
      x_.size() == s.particles.size() + walls.num_vertices()) {
    return ParticleView{x_, y_, radius_};
  }
  const ParticleView view = Fill(s, s.particles.x, s.particles.y, false);
  filled_stamp_ = s.step_stamp;
  filled_topology_ = s.topology_version;
  return view;
}

ParticleView FluidVertices::AtDetection(const LiveState& s) {
  return Fill(s, s.detection_x, s.detection_y, true);
}

ParticleView FluidVertices::Fill(const LiveState& s, std::span<const double> x,
                                 std::span<const double> y, bool detected) {
  filled_stamp_ = 0;  // whatever the arrays held, CurrentInStep sets it again after a fill
  const DomainWalls& walls = s.net.domains.walls;
  const std::span<const double> radius = s.particles.radius;
  if (walls.empty()) return ParticleView{x, y, radius};
  const std::size_t n = x.size();
  const std::size_t total = n + walls.num_vertices();
  x_.resize(total);
  y_.resize(total);
  // Disks are rigid: the radii change only with the vertex count.
  if (radius_.size() != total) {
    radius_.assign(total, 0.0);
    std::copy(radius.begin(), radius.end(), radius_.begin());
  }
  // The copy is the fill's whole cost (the vertices are a few hundred): on the threads, as the
  // passes that read it are (a copy changes no bit).
  const double* from_x = x.data();
  const double* from_y = y.data();
  double* to_x = x_.data();
  double* to_y = y_.data();
  internal::ForEachShare(static_cast<std::ptrdiff_t>(n),
                         [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
                           std::copy(from_x + begin, from_x + end, to_x + begin);
                           std::copy(from_y + begin, from_y + end, to_y + begin);
                         });
  const std::span<double> vx = std::span<double>(x_).subspan(n);
  const std::span<double> vy = std::span<double>(y_).subspan(n);
  if (detected) {
    std::copy(walls.vertex_x.begin(), walls.vertex_x.end(), vx.begin());
    std::copy(walls.vertex_y.begin(), walls.vertex_y.end(), vy.begin());
  } else {
    lines_.resize(s.walls.size());
    for (std::size_t w = 0; w < s.walls.size(); ++w) {
      lines_[w] = {s.walls[w].px, s.walls[w].py, s.walls[w].nx, s.walls[w].ny};
    }
    WallVertexPositions(walls, x, y, lines_, vx, vy);
  }
  return ParticleView{x_, y_, radius_};
}

}  // namespace seep::core
