#include "seep/core/network/scene_walls.h"

#include <algorithm>
#include <limits>

namespace seep::core {

Result<std::vector<PlacedWall>> PlaceWalls(const WallsEffectSpec& spec, std::span<const double> x,
                                           std::span<const double> y,
                                           std::span<const double> radius) {
  double lo_x = std::numeric_limits<double>::infinity(), lo_y = lo_x;
  double hi_x = -lo_x, hi_y = -lo_x;
  for (std::size_t i = 0; i < x.size(); ++i) {
    lo_x = std::min(lo_x, x[i] - radius[i]);
    hi_x = std::max(hi_x, x[i] + radius[i]);
    lo_y = std::min(lo_y, y[i] - radius[i]);
    hi_y = std::max(hi_y, y[i] + radius[i]);
  }
  std::vector<PlacedWall> out;
  for (const WallSpec& w : spec.walls) {
    if (const auto& seg = w.segment) {
      PlacedWall placed;
      SEEP_ASSIGN_OR_RETURN(
          placed.wall, MakeSegmentWall(seg->x0_m, seg->y0_m, seg->x1_m, seg->y1_m, &placed.extent));
      placed.length = placed.extent.hi;
      out.push_back(placed);
      continue;
    }
    Result<DemWall> wall = Status::Ok();
    double length = 0.0;
    switch (w.side) {
      case WallSide::kLeft:
        wall = MakeWall(lo_x, lo_y, 1.0, 0.0);
        length = hi_y - lo_y;
        break;
      case WallSide::kRight:
        wall = MakeWall(hi_x, lo_y, -1.0, 0.0);
        length = hi_y - lo_y;
        break;
      case WallSide::kBottom:
        wall = MakeWall(lo_x, lo_y, 0.0, 1.0);
        length = hi_x - lo_x;
        break;
      case WallSide::kTop:
        wall = MakeWall(lo_x, hi_y, 0.0, -1.0);
        length = hi_x - lo_x;
        break;
    }
    SEEP_RETURN_IF_ERROR(wall.status());
    out.push_back({*wall, length, DemWallExtent{}});
  }
  return out;
}

std::vector<WallLine> WallLines(const std::vector<DemWall>& walls) {
  std::vector<WallLine> lines;
  lines.reserve(walls.size());
  for (const DemWall& w : walls) lines.push_back({w.px, w.py, w.nx, w.ny});
  return lines;
}

}  // namespace seep::core
