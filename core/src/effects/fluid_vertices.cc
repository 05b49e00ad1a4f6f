#include "seep/core/effects/fluid_vertices.h"

#include <algorithm>

namespace seep::core {

ParticleView FluidVertices::Current(const LiveState& s) {
  return Fill(s, s.particles.x, s.particles.y, false);
}

ParticleView FluidVertices::AtDetection(const LiveState& s) {
  return Fill(s, s.detection_x, s.detection_y, true);
}

ParticleView FluidVertices::Fill(const LiveState& s, std::span<const double> x,
                                 std::span<const double> y, bool detected) {
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
  std::copy(x.begin(), x.end(), x_.begin());
  std::copy(y.begin(), y.end(), y_.begin());
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
