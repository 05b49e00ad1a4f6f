// DemWall: an infinite straight wall (a line in 2D), e.g. a floor or a loading platen.
//
// The wall is the line through (px, py) with unit normal (nx, ny) pointing INTO the domain: a disk
// at centre c touches it when (c - p).n < radius, and the gap is (c - p).n - radius. The wall is
// rigid and has prescribed velocity (vx, vy) (a servo sets it, see servo_wall.h); MoveWalls
// advances its point. Walls are referred to by their index in a std::vector<DemWall>.
#pragma once

#include <vector>

#include "seep/core/status.h"

namespace seep::core {

struct DemWall {
  double px = 0.0, py = 0.0;  // a point of the line
  double nx = 0.0, ny = 1.0;  // unit normal into the domain
  double vx = 0.0, vy = 0.0;  // velocity (translation only)
};

// A wall through (px, py) with inward normal (nx, ny), normalised here; the normal must be finite
// and non-zero, the point finite.
Result<DemWall> MakeWall(double px, double py, double nx, double ny);

// Checks every wall (finite fields, unit normal within 1e-12), naming the wall in the message.
Status ValidateWalls(const std::vector<DemWall>& walls);

// p += v dt for every wall.
void MoveWalls(std::vector<DemWall>* walls, double dt);

}  // namespace seep::core
