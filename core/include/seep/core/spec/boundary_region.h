// BoundaryRegionSpec: a fixed pressure or a fixed flux on the domains inside a shape
// (docs/guide/walls-and-regions.md). A domain belongs to a region when its centroid lies inside the
// shape, the shape's boundary included; the network applies regions on top of the linear, radial or
// walls-only boundary (network/boundary_regions.h) at set-up and at every re-detection.
//
// Shapes, in metres in the packing's frame:
//   BoxShape        x0 <= x <= x1, y0 <= y <= y1 (x0 < x1, y0 < y1)
//   CircleShape     |(x, y) - (cx, cy)| <= r (r > 0)
//   HalfPlaneShape  nx (x - px) + ny (y - py) >= 0: the side the normal points to (normal != 0)
//   PolygonShape    a simple polygon (>= 3 vertices, either orientation, no self-intersection)
// Conditions:
//   FixedPressure   every domain of the region is held at pressure_pa
//   FixedFlux       rate_m2_s in total into the region's domains (> 0 injects, < 0 extracts),
//                   split among them in proportion to their apparent volume V_d
#pragma once

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace seep::core {

struct BoxShape {
  double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
};
struct CircleShape {
  double cx = 0.0, cy = 0.0, r = 0.0;
};
struct HalfPlaneShape {
  double px = 0.0, py = 0.0, nx = 0.0, ny = 0.0;
};
struct PolygonShape {
  std::vector<double> x, y;
};

using RegionShape = std::variant<BoxShape, CircleShape, HalfPlaneShape, PolygonShape>;

struct FixedPressure {
  double pressure_pa = 0.0;
};
struct FixedFlux {
  double rate_m2_s = 0.0;
};

using RegionCondition = std::variant<FixedPressure, FixedFlux>;

struct BoundaryRegionSpec {
  // Required, unique in the scene, [a-z0-9_]: it names the region's metrics
  // (region_<name>_flow_m2_per_s, region_<name>_domains) and, for a pressure region, its books
  // (fluid_left_region_<name>_m2).
  std::string name;
  RegionShape shape;
  RegionCondition condition;
};

// Whether (x, y) lies in the shape, its boundary included.
bool RegionContains(const RegionShape& shape, double x, double y);

// The condition's one number: pressure_pa or rate_m2_s (what a stage's region setting replaces).
double ConditionValue(const RegionCondition& condition);
void SetConditionValue(double value, RegionCondition* condition);

// The field name of the shape's or the condition's arm in a scene file ("circle", "flux_m2_s").
const char* RegionShapeName(const RegionShape& shape);
const char* RegionConditionName(const RegionCondition& condition);

}  // namespace seep::core
