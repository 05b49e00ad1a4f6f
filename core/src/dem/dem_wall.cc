// Line and segment walls: construction, validation, contact geometry and motion.
#include "seep/core/dem/dem_wall.h"

#include <algorithm>
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

Result<DemWall> MakeSegmentWall(double x0, double y0, double x1, double y1, DemWallExtent* extent) {
  if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) {
    return InvalidArgument("dem.wall.end_points: must be finite");
  }
  const double length = std::hypot(x1 - x0, y1 - y0);
  if (!(length > 0.0)) return InvalidArgument("dem.wall.end_points: must be distinct");
  // The normal on the left of the direction (x1 - x0, y1 - y0).
  SEEP_ASSIGN_OR_RETURN(DemWall wall, MakeWall(x0, y0, -(y1 - y0), x1 - x0));
  extent->lo = 0.0;
  extent->hi = length;
  return wall;
}

WallGap SegmentWallGap(const DemWall& w, const DemWallExtent& extent, double cx, double cy,
                       double r) {
  const double dx = cx - w.px, dy = cy - w.py;
  const double along = dx * w.ny - dy * w.nx;   // d . t, t = (ny, -nx)
  const double across = dx * w.nx + dy * w.ny;  // d . n
  const double beyond = along - std::clamp(along, extent.lo, extent.hi);
  if (beyond == 0.0) {
    // Facing the segment: the nearest point is the foot of the normal.
    return across >= 0.0 ? WallGap{across - r, w.nx, w.ny} : WallGap{-across - r, -w.nx, -w.ny};
  }
  // Beyond an end: the end point is the nearest point.
  const double dist = std::hypot(beyond, across);
  const double ux = (beyond * w.ny + across * w.nx) / dist;
  const double uy = (-beyond * w.nx + across * w.ny) / dist;
  return {dist - r, ux, uy};
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

Status ValidateWallExtents(const std::vector<DemWallExtent>& extents) {
  for (std::size_t k = 0; k < extents.size(); ++k) {
    const DemWallExtent& e = extents[k];
    const bool line = e.lo == -std::numeric_limits<double>::infinity() &&
                      e.hi == std::numeric_limits<double>::infinity();
    const bool segment = std::isfinite(e.lo) && std::isfinite(e.hi) && e.lo < e.hi;
    if (!line && !segment) {
      return InvalidArgument("dem.wall_extents[" + std::to_string(k) +
                             "]: must be a line (-inf, inf) or a segment lo < hi, both finite");
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
