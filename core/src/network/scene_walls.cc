#include "seep/core/network/scene_walls.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace seep::core {
namespace {

// A side wall at the outermost disk surface, *edge = x + r (or x - r, y + r, y - r), moved out by
// ulps until no disk overlaps the wall make(*edge) in the DEM's own gap arithmetic (LineWallGap).
// Placed at the rounded sum alone, the outermost disk overlaps it by up to half an ulp or not, as
// the rounding at the sample's coordinates falls; a contact's dashpot engages at once, so whether
// a run starts with that contact would depend on where the sample sits (the translation law of
// the metamorphic suite found it). `outward` is -inf or +inf along the coordinate.
template <typename Make>
Status ClearOfEveryDisk(std::span<const double> x, std::span<const double> y,
                        std::span<const double> radius, double outward, double* edge, Make make) {
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const DemWall wall, make(*edge));
    double smallest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < x.size(); ++i) {
      smallest = std::min(smallest, LineWallGap(wall, x[i], y[i], radius[i]).gap);
    }
    if (!(smallest < 0.0)) return Status::Ok();
    *edge = std::nextafter(*edge, outward);
  }
}

}  // namespace

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
  // Each side's line as MakeWall takes it below, moved clear of every disk.
  const double inf = std::numeric_limits<double>::infinity();
  SEEP_RETURN_IF_ERROR(ClearOfEveryDisk(x, y, radius, -inf, &lo_x,
                                        [&](double e) { return MakeWall(e, lo_y, 1.0, 0.0); }));
  SEEP_RETURN_IF_ERROR(ClearOfEveryDisk(x, y, radius, inf, &hi_x,
                                        [&](double e) { return MakeWall(e, lo_y, -1.0, 0.0); }));
  SEEP_RETURN_IF_ERROR(ClearOfEveryDisk(x, y, radius, -inf, &lo_y,
                                        [&](double e) { return MakeWall(lo_x, e, 0.0, 1.0); }));
  SEEP_RETURN_IF_ERROR(ClearOfEveryDisk(x, y, radius, inf, &hi_y,
                                        [&](double e) { return MakeWall(lo_x, e, 0.0, -1.0); }));
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
