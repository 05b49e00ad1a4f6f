// DemWall: a rigid straight wall (a line in 2D, or a segment of it), e.g. a floor or a platen.
//
// The wall is the line through (px, py) with unit normal (nx, ny) pointing INTO the domain: a disk
// at centre c touches it when (c - p).n < radius, and the gap is (c - p).n - radius. The wall is
// rigid and has prescribed velocity (vx, vy) (a servo sets it, see servo_wall.h); MoveWalls
// advances its point. Walls are referred to by their index in a std::vector<DemWall>.
//
// A wall may also be a finite segment of its line (DemWallExtent): the part from p + lo t to
// p + hi t along the tangent t = (ny, -nx) (the normal is on the left of t). A disk then touches
// the nearest point of the segment, an end acting as a disk of radius 0, so disks pass beyond the
// ends; the segment is a thin rigid plate (touched from either face). The extent is fixed when the
// wall is placed and is not part of the moving state (DemContactForces::SetWallExtents).
#pragma once

#include <limits>
#include <vector>

#include "seep/core/status.h"

namespace seep::core {

struct DemWall {
  double px = 0.0, py = 0.0;  // a point of the line
  double nx = 0.0, ny = 1.0;  // unit normal into the domain
  double vx = 0.0, vy = 0.0;  // velocity (translation only)
};

// The part of a wall's line that exists, along t = (ny, -nx) from the wall's point: a line when
// both ends are infinite (the default).
struct DemWallExtent {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool finite() const { return lo > -std::numeric_limits<double>::infinity(); }
};

// Where a disk (centre cx, cy, radius r) stands to a wall: the surface gap (< 0 overlap) and the
// unit normal (ux, uy) from the wall to the centre. For a line: the signed distance along the
// wall's normal, u = n. For a segment: the distance to its nearest point (u = n when the centre
// is exactly on the segment).
struct WallGap {
  double gap = 0.0;
  double ux = 0.0, uy = 1.0;
};
inline WallGap LineWallGap(const DemWall& w, double cx, double cy, double r) {
  return {(cx - w.px) * w.nx + (cy - w.py) * w.ny - r, w.nx, w.ny};
}
WallGap SegmentWallGap(const DemWall& w, const DemWallExtent& extent, double cx, double cy,
                       double r);

// A wall through (px, py) with inward normal (nx, ny), normalised here; the normal must be finite
// and non-zero, the point finite.
Result<DemWall> MakeWall(double px, double py, double nx, double ny);

// The wall from (x0, y0) to (x1, y1): its point is (x0, y0), its normal the unit vector on the
// left of the direction of travel, and its extent [0, length]. The end points must be finite and
// distinct.
Result<DemWall> MakeSegmentWall(double x0, double y0, double x1, double y1, DemWallExtent* extent);

// Checks every wall (finite fields, unit normal within 1e-12), naming the wall in the message.
Status ValidateWalls(const std::vector<DemWall>& walls);

// Checks extents (lo < hi, lo finite exactly when hi is), naming the wall in the message.
Status ValidateWallExtents(const std::vector<DemWallExtent>& extents);

// p += v dt for every wall.
void MoveWalls(std::vector<DemWall>* walls, double dt);

}  // namespace seep::core
