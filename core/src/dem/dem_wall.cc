// Line walls: construction, validation and motion.
#include "seep/core/dem/dem_wall.h"

#include <cmath>
#include <string>

namespace seep::core {

Result<DemWall> MakeWall(double px, double py, double nx, double ny) {
  if (!std::isfinite(px) || !std::isfinite(py)) {
    return InvalidArgument("dem.wall.point: must be finite");
  }
  const double len = std::hypot(nx, ny);
  if (!std::isfinite(len) || len == 0.0) {
    return InvalidArgument("dem.wall.normal: must be finite and non-zero");
  }
  DemWall w;
  w.px = px;
  w.py = py;
  w.nx = nx / len;
  w.ny = ny / len;
  return w;
}

Status ValidateWalls(const std::vector<DemWall>& walls) {
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const DemWall& w = walls[k];
    const std::string name = "dem.walls[" + std::to_string(k) + "]";
    if (!std::isfinite(w.px) || !std::isfinite(w.py) || !std::isfinite(w.vx) ||
        !std::isfinite(w.vy)) {
      return InvalidArgument(name + ": point and velocity must be finite");
    }
    const double len = std::hypot(w.nx, w.ny);
    if (!(std::abs(len - 1.0) <= 1e-12)) {
      return InvalidArgument(name + ".normal: must be a unit vector (length " +
                             std::to_string(len) + ")");
    }
  }
  return Status::Ok();
}

void MoveWalls(std::vector<DemWall>* walls, double dt) {
  for (DemWall& w : *walls) {
    w.px += w.vx * dt;
    w.py += w.vy * dt;
  }
}

}  // namespace seep::core
