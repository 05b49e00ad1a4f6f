// Validation of a scene's boundary regions (spec/boundary_region.h): names, shapes, conditions,
// and that no two regions whose shapes overlap give a domain two different conditions — neither
// in the scene nor in any stage.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "field_error.h"
#include "region_overlap.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {
namespace {

using spec_internal::Frame;

// Bounds that keep a typo from making the pairwise overlap test (O(vertices^2) per pair) run for
// minutes; real scenes use a handful of regions of a few dozen vertices.
constexpr std::size_t kMaxRegions = 256;
constexpr std::size_t kMaxPolygonVertices = 4096;
constexpr std::size_t kMaxNameLength = 64;

// Shapes within this fraction of the scene's extent of each other count as overlapping: far
// below any grain, far above rounding.
constexpr double kRelativeTolerance = 1e-9;
// A half-plane is clipped to the scene's extent enlarged this many times about its centre.
constexpr double kFrameScale = 10.0;

using spec_internal::Bad;
using spec_internal::RequireFinite;

Status ValidateName(const std::string& at, const std::string& name) {
  if (name.empty()) return Bad(at + ".name", "is required (it names the region's metrics)");
  if (name.size() > kMaxNameLength) {
    return Bad(at + ".name",
               fmt::format("at most {} characters (got {})", kMaxNameLength, name.size()));
  }
  const bool plain = std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
  if (!plain) {
    return Bad(
        at + ".name",
        fmt::format("only a-z, 0-9 and _ (it becomes part of metric names; got '{}')", name));
  }
  return Status::Ok();
}

Status ValidatePolygon(const std::string& at, const PolygonShape& p) {
  if (p.x.size() != p.y.size()) {
    return Bad(at, fmt::format("x_m and y_m must have equal lengths (got {} and {})", p.x.size(),
                               p.y.size()));
  }
  const std::size_t n = p.x.size();
  if (n < 3) return Bad(at, fmt::format("needs at least 3 vertices (got {})", n));
  if (n > kMaxPolygonVertices) {
    return Bad(at, fmt::format("at most {} vertices (got {})", kMaxPolygonVertices, n));
  }
  for (std::size_t k = 0; k < n; ++k) {
    SEEP_RETURN_IF_ERROR(RequireFinite(fmt::format("{}.x_m[{}]", at, k), p.x[k]));
    SEEP_RETURN_IF_ERROR(RequireFinite(fmt::format("{}.y_m[{}]", at, k), p.y[k]));
  }
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t before = (k + n - 1) % n;
    if (p.x[k] == p.x[before] && p.y[k] == p.y[before]) {
      return Bad(at,
                 fmt::format("vertex {} repeats vertex {} ({}, {})", k, before, p.x[k], p.y[k]));
    }
  }
  const auto [x0, x1] = std::minmax_element(p.x.begin(), p.x.end());
  const auto [y0, y1] = std::minmax_element(p.y.begin(), p.y.end());
  const double extent = std::hypot(*x1 - *x0, *y1 - *y0);
  if (!(std::abs(spec_internal::TwiceSignedArea(p.x, p.y)) > 1e-12 * extent * extent)) {
    return Bad(at, "has no area (its vertices lie on one line)");
  }
  std::size_t first = 0, second = 0;
  if (spec_internal::SelfIntersects(p.x, p.y, &first, &second)) {
    return Bad(at, fmt::format("edges {} and {} meet (edge k runs from vertex k to the next); a "
                               "region's polygon must be simple",
                               first, second));
  }
  return Status::Ok();
}

Status ValidateShape(const std::string& region, const RegionShape& shape) {
  const std::string at = fmt::format("{}.{}", region, RegionShapeName(shape));
  return std::visit(
      [&at](const auto& s) -> Status {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, BoxShape>) {
          for (const auto& [field, value] :
               {std::pair{"x0_m", s.x0}, {"y0_m", s.y0}, {"x1_m", s.x1}, {"y1_m", s.y1}}) {
            SEEP_RETURN_IF_ERROR(RequireFinite(at + "." + field, value));
          }
          if (!(s.x0 < s.x1)) {
            return Bad(at + ".x1_m", fmt::format("must be > x0_m (got {} <= {})", s.x1, s.x0));
          }
          if (!(s.y0 < s.y1)) {
            return Bad(at + ".y1_m", fmt::format("must be > y0_m (got {} <= {})", s.y1, s.y0));
          }
        } else if constexpr (std::is_same_v<T, CircleShape>) {
          SEEP_RETURN_IF_ERROR(RequireFinite(at + ".cx_m", s.cx));
          SEEP_RETURN_IF_ERROR(RequireFinite(at + ".cy_m", s.cy));
          if (!(std::isfinite(s.r) && s.r > 0.0)) {
            return Bad(at + ".r_m", fmt::format("must be a finite number > 0 (got {})", s.r));
          }
        } else if constexpr (std::is_same_v<T, HalfPlaneShape>) {
          for (const auto& [field, value] :
               {std::pair{"px_m", s.px}, {"py_m", s.py}, {"nx", s.nx}, {"ny", s.ny}}) {
            SEEP_RETURN_IF_ERROR(RequireFinite(at + "." + field, value));
          }
          if (s.nx == 0.0 && s.ny == 0.0) {
            return Bad(at, "the normal (nx, ny) must not be zero (it points into the region)");
          }
        } else {
          return ValidatePolygon(at, s);
        }
        return Status::Ok();
      },
      shape);
}

// The packing's extent as the scene describes it (before any particle moves).
std::optional<Frame> PackingExtent(const PackingSpec& packing) {
  if (const auto* l = std::get_if<LatticePackingSpec>(&packing.source)) {
    const double r = l->radius_m;
    if (l->kind == LatticeKind::kSquare)
      return Frame{0.0, 0.0, 2.0 * r * l->columns, 2.0 * r * l->rows};
    return Frame{0.0, 0.0, r * (2.0 * l->columns + 1.0),
                 r * (2.0 + std::sqrt(3.0) * (l->rows - 1.0))};
  }
  if (const auto* random = std::get_if<RandomPackingSpec>(&packing.source)) {
    return Frame{0.0, 0.0, random->width_m, random->height_m};
  }
  const auto& list = std::get<ParticleListSpec>(packing.source);
  if (list.x_m.empty()) return std::nullopt;
  Frame f{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (std::size_t i = 0; i < list.x_m.size() && i < list.radius_m.size(); ++i) {
    f.x0 = std::min(f.x0, list.x_m[i] - list.radius_m[i]);
    f.x1 = std::max(f.x1, list.x_m[i] + list.radius_m[i]);
    f.y0 = std::min(f.y0, list.y_m[i] - list.radius_m[i]);
    f.y1 = std::max(f.y1, list.y_m[i] + list.radius_m[i]);
  }
  return f;
}

// The box every shape, every half-plane's anchor point and the packing lie in.
Frame SceneExtent(const SceneSpec& scene) {
  Frame f{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  const auto add = [&f](double x0, double y0, double x1, double y1) {
    f = {std::min(f.x0, x0), std::min(f.y0, y0), std::max(f.x1, x1), std::max(f.y1, y1)};
  };
  if (const auto packing = PackingExtent(scene.packing)) {
    add(packing->x0, packing->y0, packing->x1, packing->y1);
  }
  for (const BoundaryRegionSpec& region : scene.boundary.regions) {
    std::visit(
        [&add](const auto& s) {
          using T = std::decay_t<decltype(s)>;
          if constexpr (std::is_same_v<T, BoxShape>) {
            add(s.x0, s.y0, s.x1, s.y1);
          } else if constexpr (std::is_same_v<T, CircleShape>) {
            add(s.cx - s.r, s.cy - s.r, s.cx + s.r, s.cy + s.r);
          } else if constexpr (std::is_same_v<T, HalfPlaneShape>) {
            add(s.px, s.py, s.px, s.py);
          } else {
            for (std::size_t k = 0; k < s.x.size(); ++k) add(s.x[k], s.y[k], s.x[k], s.y[k]);
          }
        },
        region.shape);
  }
  return f;
}

bool SameSetting(const std::optional<SettingSpec>& a, const std::optional<SettingSpec>& b) {
  if (!a || !b) return !a && !b;
  if (a->index() != b->index()) return false;
  if (const double* v = std::get_if<double>(&*a)) return *v == std::get<double>(*b);
  const auto& sa = std::get<ScheduleSpec>(*a);
  const auto& sb = std::get<ScheduleSpec>(*b);
  return sa.time_s == sb.time_s && sa.value == sb.value;
}

// What a stage sets region `index` to (unset: it keeps the value before).
std::optional<SettingSpec> StageValue(const StageSpec& stage, std::size_t index) {
  for (const StageRegionSpec& r : stage.regions) {
    if (r.region == index) return r.value;
  }
  return std::nullopt;
}

// Two overlapping regions with the same condition must keep it the same through every stage.
Status ValidateStagesKeepThemEqual(const SceneSpec& scene, std::size_t a, std::size_t b) {
  const auto& regions = scene.boundary.regions;
  for (std::size_t s = 0; s < scene.stages.size(); ++s) {
    if (SameSetting(StageValue(scene.stages[s], a), StageValue(scene.stages[s], b))) continue;
    return Bad(fmt::format("scene.stages[{}].regions", s),
               fmt::format("regions[{}] ('{}') and regions[{}] ('{}') overlap, so a stage must "
                           "set both to the same value or neither (a domain in both would have "
                           "two conditions)",
                           a, regions[a].name, b, regions[b].name));
  }
  return Status::Ok();
}

}  // namespace

Status ValidateBoundaryRegions(const SceneSpec& scene) {
  const std::vector<BoundaryRegionSpec>& regions = scene.boundary.regions;
  if (regions.empty()) return Status::Ok();
  if (!HasFlow(scene)) {
    return Bad("scene.boundary.regions", "the scene has no flow (list the flow effect)");
  }
  if (regions.size() > kMaxRegions) {
    return Bad("scene.boundary.regions",
               fmt::format("at most {} regions (got {})", kMaxRegions, regions.size()));
  }
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const BoundaryRegionSpec& region = regions[i];
    const std::string at = fmt::format("scene.boundary.regions[{}]", i);
    SEEP_RETURN_IF_ERROR(ValidateName(at, region.name));
    for (std::size_t j = 0; j < i; ++j) {
      if (regions[j].name == region.name) {
        return Bad(at + ".name", fmt::format("'{}' is the name of regions[{}] too (names are "
                                             "unique: they name the metrics)",
                                             region.name, j));
      }
    }
    SEEP_RETURN_IF_ERROR(ValidateShape(at, region.shape));
    SEEP_RETURN_IF_ERROR(
        RequireFinite(fmt::format("{}.{}", at, RegionConditionName(region.condition)),
                      ConditionValue(region.condition)));
  }
  const Frame extent = SceneExtent(scene);
  const double size = std::max({extent.x1 - extent.x0, extent.y1 - extent.y0, 0.0});
  const double half = size > 0.0 ? 0.5 * kFrameScale * size : 1.0;
  const double cx = 0.5 * (extent.x0 + extent.x1), cy = 0.5 * (extent.y0 + extent.y1);
  const Frame frame{cx - half, cy - half, cx + half, cy + half};
  const double tolerance = kRelativeTolerance * std::max(size, 1e-300);
  for (std::size_t i = 0; i < regions.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const bool same =
          regions[i].condition.index() == regions[j].condition.index() &&
          ConditionValue(regions[i].condition) == ConditionValue(regions[j].condition);
      if (same && scene.stages.empty()) continue;  // nothing can set them apart
      if (!spec_internal::ShapesOverlap(regions[i].shape, regions[j].shape, frame, tolerance)) {
        continue;
      }
      if (!same) {
        return Bad(fmt::format("scene.boundary.regions[{}] ('{}')", i, regions[i].name),
                   fmt::format("overlaps regions[{}] ('{}') with a different condition; a "
                               "domain in both would have two",
                               j, regions[j].name));
      }
      SEEP_RETURN_IF_ERROR(ValidateStagesKeepThemEqual(scene, j, i));
    }
  }
  return Status::Ok();
}

}  // namespace seep::core
