// seep.v1.BoundaryRegion -> core::BoundaryRegionSpec (wire checks only: a shape and a condition
// set). Names, shapes, values and overlaps are core::ValidateScene's. Errors name the field by
// its path: "scene.boundary.regions[0]: set one shape (box, circle, half_plane, polygon)".
#pragma once

#include <cstddef>
#include <vector>

#include "seep/core/spec/boundary_region.h"
#include "seep/core/status.h"
#include "seep/v1/scene.pb.h"

namespace seep::service {

// Appends the region to *out (a status return, as AppendStageFromProto).
core::Status AppendRegionFromProto(const v1::BoundaryRegion& region, std::size_t index,
                                   std::vector<core::BoundaryRegionSpec>* out);

}  // namespace seep::service
