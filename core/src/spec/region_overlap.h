// Plane geometry for the validation of boundary regions (boundary_region_validation.cc): whether
// a polygon is simple, and whether two regions' shapes share area.
//
// The overlap test is conservative: shapes that touch, or come within `tolerance` of each other,
// count as overlapping (a centroid on a shared edge would lie in both, boundaries being inside).
// Circles are tested exactly (centre distances against the radii), never through a polygon that
// could miss a sliver of the circle. A half-plane is clipped to the `frame`, a box far larger than
// the sample and every other shape: overlap farther out than that cannot hold a domain, and two
// nearly parallel half-planes that meet only there are not refused.
#pragma once

#include <cstddef>
#include <vector>

#include "seep/core/spec/boundary_region.h"

namespace seep::core::spec_internal {

struct Frame {
  double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
};

// Twice the signed area of the polygon (> 0 counter-clockwise).
double TwiceSignedArea(const std::vector<double>& x, const std::vector<double>& y);

// Whether two edges of the closed polygon meet other than where neighbours share a vertex, or
// two neighbours fold back onto each other; *first and *second name the edges (edge k runs from
// vertex k to vertex k + 1).
bool SelfIntersects(const std::vector<double>& x, const std::vector<double>& y, std::size_t* first,
                    std::size_t* second);

// Whether the shapes share area, within `tolerance` (m) and inside `frame` for half-planes.
bool ShapesOverlap(const RegionShape& a, const RegionShape& b, const Frame& frame,
                   double tolerance);

}  // namespace seep::core::spec_internal
