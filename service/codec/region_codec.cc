#include "codec/region_codec.h"

#include <fmt/format.h>

#include <string>
#include <utility>

namespace seep::service {

core::Status AppendRegionFromProto(const v1::BoundaryRegion& region, std::size_t index,
                                   std::vector<core::BoundaryRegionSpec>* out) {
  const std::string path = fmt::format("scene.boundary.regions[{}]", index);
  core::BoundaryRegionSpec spec;
  spec.name = region.name();
  switch (region.shape_case()) {
    case v1::BoundaryRegion::kBox: {
      const v1::Box& b = region.box();
      spec.shape = core::BoxShape{b.x0_m(), b.y0_m(), b.x1_m(), b.y1_m()};
      break;
    }
    case v1::BoundaryRegion::kCircle: {
      const v1::Circle& c = region.circle();
      spec.shape = core::CircleShape{c.cx_m(), c.cy_m(), c.r_m()};
      break;
    }
    case v1::BoundaryRegion::kHalfPlane: {
      const v1::HalfPlane& h = region.half_plane();
      spec.shape = core::HalfPlaneShape{h.px_m(), h.py_m(), h.nx(), h.ny()};
      break;
    }
    case v1::BoundaryRegion::kPolygon: {
      const v1::Polygon& p = region.polygon();
      // Equal lengths and the vertices are core's checks: it names the vertex.
      spec.shape =
          core::PolygonShape{{p.x_m().begin(), p.x_m().end()}, {p.y_m().begin(), p.y_m().end()}};
      break;
    }
    case v1::BoundaryRegion::SHAPE_NOT_SET:
      return core::InvalidArgument(
          fmt::format("{}: set one shape (box, circle, half_plane, polygon)", path));
  }
  switch (region.condition_case()) {
    case v1::BoundaryRegion::kPressurePa:
      spec.condition = core::FixedPressure{region.pressure_pa()};
      break;
    case v1::BoundaryRegion::kFluxM2S:
      spec.condition = core::FixedFlux{region.flux_m2_s()};
      break;
    case v1::BoundaryRegion::CONDITION_NOT_SET:
      return core::InvalidArgument(
          fmt::format("{}: set one condition (pressure_pa, flux_m2_s)", path));
  }
  out->push_back(std::move(spec));
  return core::Status::Ok();
}

}  // namespace seep::service
