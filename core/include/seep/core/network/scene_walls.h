// The walls of a scene where the walls effect places them, for the DEM and for the fluid network
// alike: each side wall touches the outermost disk surface of its side of the packing's bounding
// box; a segment wall is where its end points say.
#pragma once

#include <span>
#include <vector>

#include "seep/core/dem/dem_wall.h"
#include "seep/core/geometry/domain_walls.h"
#include "seep/core/spec/effect_spec.h"
#include "seep/core/status.h"

namespace seep::core {

struct PlacedWall {
  DemWall wall;
  double length = 0.0;   // the loaded length: the bounding box's side (the servo's stress basis)
                         // or the segment's length
  DemWallExtent extent;  // a line for a side wall, [0, length] for a segment wall
};

// One per spec.walls entry, in that order, for the disks (x, y, radius).
Result<std::vector<PlacedWall>> PlaceWalls(const WallsEffectSpec& spec, std::span<const double> x,
                                           std::span<const double> y,
                                           std::span<const double> radius);

// The lines of DEM walls, for the detection.
std::vector<WallLine> WallLines(const std::vector<DemWall>& walls);

}  // namespace seep::core
