#include "seep/core/spec/boundary_region.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <type_traits>

namespace seep::core {
namespace {

// Whether (x, y) lies on the segment from (ax, ay) to (bx, by): collinear to rounding and within
// its extent. A centroid exactly on a polygon's edge counts as inside.
bool OnSegment(double ax, double ay, double bx, double by, double x, double y) {
  const double cross = (bx - ax) * (y - ay) - (by - ay) * (x - ax);
  const double scale =
      (std::abs(bx - ax) + std::abs(by - ay)) * (std::abs(x - ax) + std::abs(y - ay));
  if (std::abs(cross) > 1e-14 * scale) return false;
  return std::min(ax, bx) <= x && x <= std::max(ax, bx) && std::min(ay, by) <= y &&
         y <= std::max(ay, by);
}

bool PolygonContains(const PolygonShape& p, double x, double y) {
  const std::size_t n = p.x.size();
  bool inside = false;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    if (OnSegment(p.x[j], p.y[j], p.x[i], p.y[i], x, y)) return true;
    // Crossing number: the edge straddles the horizontal through y and crosses it right of x.
    if ((p.y[i] > y) != (p.y[j] > y) &&
        x < p.x[i] + (y - p.y[i]) * (p.x[j] - p.x[i]) / (p.y[j] - p.y[i])) {
      inside = !inside;
    }
  }
  return inside;
}

}  // namespace

bool RegionContains(const RegionShape& shape, double x, double y) {
  return std::visit(
      [x, y](const auto& s) -> bool {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, BoxShape>) {
          return s.x0 <= x && x <= s.x1 && s.y0 <= y && y <= s.y1;
        } else if constexpr (std::is_same_v<T, CircleShape>) {
          const double dx = x - s.cx, dy = y - s.cy;
          return dx * dx + dy * dy <= s.r * s.r;
        } else if constexpr (std::is_same_v<T, HalfPlaneShape>) {
          return s.nx * (x - s.px) + s.ny * (y - s.py) >= 0.0;
        } else {
          return s.x.size() >= 3 && PolygonContains(s, x, y);
        }
      },
      shape);
}

double ConditionValue(const RegionCondition& condition) {
  if (const auto* p = std::get_if<FixedPressure>(&condition)) return p->pressure_pa;
  return std::get<FixedFlux>(condition).rate_m2_s;
}

void SetConditionValue(double value, RegionCondition* condition) {
  if (auto* p = std::get_if<FixedPressure>(condition)) {
    p->pressure_pa = value;
  } else {
    std::get<FixedFlux>(*condition).rate_m2_s = value;
  }
}

const char* RegionShapeName(const RegionShape& shape) {
  static constexpr const char* kNames[] = {"box", "circle", "half_plane", "polygon"};
  static_assert(std::size(kNames) == std::variant_size_v<RegionShape>);
  return kNames[shape.index()];
}

const char* RegionConditionName(const RegionCondition& condition) {
  return std::holds_alternative<FixedPressure>(condition) ? "pressure_pa" : "flux_m2_s";
}

}  // namespace seep::core
