// Validation of a scene's effect list: each effect's fields, then how the effects combine.
#include <fmt/format.h>

#include <cmath>
#include <string>
#include <utility>

#include "seep/core/dem/contact_law.h"
#include "seep/core/dem/parallel_bond.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {
namespace {

std::string Field(std::size_t index, const EffectSpec& spec, const char* field) {
  return fmt::format("scene.effects[{}].{}{}{}", index, EffectName(spec), *field ? "." : "", field);
}

bool PositiveFinite(double v) { return std::isfinite(v) && v > 0.0; }

// Re-prefixes a core validator's message ("dem.contact.kn: ...") with the list entry.
Status Prefixed(std::size_t index, const EffectSpec& spec, const Status& status) {
  if (status.ok()) return status;
  return InvalidArgument(fmt::format("{}: {}", Field(index, spec, ""), status.message()));
}

struct FieldValidator {
  std::size_t index;
  const EffectSpec& spec;
  bool staged;  // the scene has stages (they may switch an effect's setting off and on)

  Status Bad(const char* field, const std::string& why) const {
    return InvalidArgument(fmt::format("{}: {}", Field(index, spec, field), why));
  }

  Status operator()(const ContactsEffectSpec& c) const {
    SEEP_RETURN_IF_ERROR(Prefixed(index, spec, ValidateContactLawParams(c.law)));
    if (!PositiveFinite(c.density_kg_m3)) {
      return Bad("density_kg_m3",
                 fmt::format("must be a finite number > 0 (got {})", c.density_kg_m3));
    }
    if (!std::isfinite(c.skin_m) || c.skin_m < 0.0) {
      return Bad("skin_m", fmt::format("must be a finite number >= 0 (got {})", c.skin_m));
    }
    if (!PositiveFinite(c.dt_safety) || c.dt_safety > 1.0) {
      return Bad("dt_safety", fmt::format("must lie in (0, 1] (got {})", c.dt_safety));
    }
    return Status::Ok();
  }
  Status operator()(const BondsEffectSpec& b) const {
    SEEP_RETURN_IF_ERROR(Prefixed(index, spec, ValidateBondParams(b.params)));
    if (!std::isfinite(b.tolerance_m) || b.tolerance_m < 0.0) {
      return Bad("tolerance_m",
                 fmt::format("must be a finite number >= 0 (got {})", b.tolerance_m));
    }
    return Status::Ok();
  }
  Status operator()(const GravityEffectSpec& g) const {
    if (!std::isfinite(g.gx_m_s2) || !std::isfinite(g.gy_m_s2)) {
      return Bad("gy_m_s2", fmt::format("must be finite (got {}, {})", g.gx_m_s2, g.gy_m_s2));
    }
    return Status::Ok();
  }
  Status operator()(const FluidForcesEffectSpec&) const { return Status::Ok(); }
  Status operator()(const LocalDampingEffectSpec& d) const {
    if (!std::isfinite(d.alpha) || d.alpha < 0.0 || d.alpha >= 1.0) {
      return Bad("alpha", fmt::format("must lie in [0, 1) (got {})", d.alpha));
    }
    return Status::Ok();
  }
  Status operator()(const WallsEffectSpec& w) const {
    if (w.walls.empty()) return Bad("walls", "lists no wall");
    bool seen[4] = {false, false, false, false};
    for (std::size_t k = 0; k < w.walls.size(); ++k) {
      const WallSpec& wall = w.walls[k];
      const std::string field = fmt::format("walls[{}]", k);
      if (const auto& seg = wall.segment) {
        SEEP_RETURN_IF_ERROR(Segment(field, *seg));
      } else {
        const auto side = static_cast<std::size_t>(wall.side);
        if (seen[side]) return Bad(field.c_str(), "a second wall on the same side");
        seen[side] = true;
      }
      if (const auto& v = wall.normal_velocity_m_s) {
        if (!std::isfinite(*v)) {
          return Bad((field + ".normal_velocity_m_s").c_str(),
                     fmt::format("must be finite (got {})", *v));
        }
        if (wall.servo_stress_pa != 0.0) {
          return Bad((field + ".normal_velocity_m_s").c_str(),
                     "a wall is servo-controlled (servo_stress_pa) or velocity-controlled, not "
                     "both");
        }
      }
      if (!std::isfinite(wall.servo_stress_pa) || wall.servo_stress_pa < 0.0) {
        return Bad((field + ".servo_stress_pa").c_str(),
                   fmt::format("must be a finite number >= 0 (got {})", wall.servo_stress_pa));
      }
      if (wall.servo_stress_pa > 0.0) {
        if (!PositiveFinite(wall.servo_max_speed_m_s)) {
          return Bad((field + ".servo_max_speed_m_s").c_str(),
                     fmt::format("a servo wall needs a finite speed limit > 0 (got {})",
                                 wall.servo_max_speed_m_s));
        }
        if (!PositiveFinite(wall.servo_gain_fraction) || wall.servo_gain_fraction > 1.0) {
          return Bad((field + ".servo_gain_fraction").c_str(),
                     fmt::format("must lie in (0, 1] (got {})", wall.servo_gain_fraction));
        }
      }
      if (const auto& drain = wall.drain) {
        if (!std::isfinite(drain->pressure_pa)) {
          return Bad(
              (field + ".drain.pressure_pa").c_str(),
              fmt::format("a drained wall needs a finite pressure (got {})", drain->pressure_pa));
        }
        if (!PositiveFinite(drain->conductance_m_per_pa_s)) {
          return Bad(
              (field + ".drain.conductance_m_per_pa_s").c_str(),
              fmt::format("must be a finite number > 0 (got {})", drain->conductance_m_per_pa_s));
        }
      }
    }
    return Status::Ok();
  }
  // Finite end points, distinct.
  Status Segment(const std::string& field, const WallSegmentSpec& seg) const {
    const std::pair<const char*, double> ends[] = {
        {"x0_m", seg.x0_m}, {"y0_m", seg.y0_m}, {"x1_m", seg.x1_m}, {"y1_m", seg.y1_m}};
    for (const auto& [name, value] : ends) {
      if (!std::isfinite(value)) {
        return Bad(fmt::format("{}.{}", field, name).c_str(),
                   fmt::format("must be finite (got {})", value));
      }
    }
    if (seg.x0_m == seg.x1_m && seg.y0_m == seg.y1_m) {
      return Bad((field + ".x1_m").c_str(),
                 fmt::format("the segment has zero length: (x1_m, y1_m) = (x0_m, y0_m) = ({}, {})",
                             seg.x0_m, seg.y0_m));
    }
    return Status::Ok();
  }
  Status operator()(const VolumeChangeEffectSpec&) const { return Status::Ok(); }
  Status operator()(const ApertureUpdateEffectSpec&) const { return Status::Ok(); }
  Status operator()(const FlowEffectSpec&) const { return Status::Ok(); }
  Status operator()(const RedetectionEffectSpec&) const { return Status::Ok(); }
  Status operator()(const InjectionEffectSpec& i) const {
    // A staged scene may start shut in (rate 0) and have a stage open the well.
    if (staged ? !(std::isfinite(i.rate_m2_s) && i.rate_m2_s >= 0.0)
               : !PositiveFinite(i.rate_m2_s)) {
      return Bad("rate_m2_s", fmt::format("must be a finite number {} 0 (got {})",
                                          staged ? ">=" : ">", i.rate_m2_s));
    }
    return Status::Ok();
  }
};

}  // namespace

std::string_view EffectName(std::size_t kind) {
  static constexpr std::string_view kNames[] = {
      "contacts",      "bonds",           "gravity", "fluid_forces", "local_damping", "walls",
      "volume_change", "aperture_update", "flow",    "redetection",  "injection"};
  static_assert(std::size(kNames) == kEffectKinds, "one name per EffectSpec arm");
  return kind < kEffectKinds ? kNames[kind] : std::string_view("unknown");
}

std::string WallName(const WallSpec& wall, std::size_t k) {
  return wall.segment ? fmt::format("segment{}", k) : std::string(WallSideName(wall.side));
}

Status ValidateEffects(const SceneSpec& scene) {
  bool listed[kEffectKinds] = {};
  for (std::size_t k = 0; k < scene.effects.size(); ++k) {
    const EffectSpec& e = scene.effects[k];
    if (listed[e.index()]) {
      return InvalidArgument(
          fmt::format("{}: listed twice (each effect at most once)", Field(k, e, "")));
    }
    listed[e.index()] = true;
    SEEP_RETURN_IF_ERROR(std::visit(FieldValidator{k, e, !scene.stages.empty()}, e));
  }
  const bool mechanics = HasMechanics(scene);
  const bool flow = HasFlow(scene);
  for (std::size_t k = 0; k < scene.effects.size(); ++k) {
    const EffectSpec& e = scene.effects[k];
    const bool mechanical = std::holds_alternative<BondsEffectSpec>(e) ||
                            std::holds_alternative<GravityEffectSpec>(e) ||
                            std::holds_alternative<LocalDampingEffectSpec>(e) ||
                            std::holds_alternative<WallsEffectSpec>(e);
    const bool coupling = std::holds_alternative<FluidForcesEffectSpec>(e) ||
                          std::holds_alternative<VolumeChangeEffectSpec>(e) ||
                          std::holds_alternative<ApertureUpdateEffectSpec>(e) ||
                          std::holds_alternative<RedetectionEffectSpec>(e);
    // Gravity on a frozen packing weighs the fluid alone (the disks do not move).
    const bool weighs_fluid_only =
        std::holds_alternative<GravityEffectSpec>(e) && scene.fluid.density_kg_m3 > 0.0;
    if ((mechanical || coupling) && !mechanics && !weighs_fluid_only) {
      return InvalidArgument(fmt::format(
          "{}: requires the contacts effect (without it the particles do not move){}",
          Field(k, e, ""),
          std::holds_alternative<GravityEffectSpec>(e)
              ? "; on a frozen packing gravity can weigh the fluid: set fluid.density_kg_m3 > 0"
              : ""));
    }
    if ((coupling || std::holds_alternative<InjectionEffectSpec>(e)) && !flow) {
      return InvalidArgument(fmt::format(
          "{}: requires the flow effect (there is no fluid to couple)", Field(k, e, "")));
    }
    // With flow the walls bound the fluid, and the fluid's walls are lines clipped against each
    // other (domain_walls.h): a segment, which disks pass beyond, has no fluid model yet.
    if (const auto* walls = std::get_if<WallsEffectSpec>(&e); walls != nullptr && flow) {
      for (std::size_t w = 0; w < walls->walls.size(); ++w) {
        if (!walls->walls[w].segment) continue;
        return InvalidArgument(fmt::format(
            "{}: a wall given by its end points cannot bound the fluid (walls in the fluid are "
            "the sides of the packing's box); give it a side, or drop the flow effect",
            Field(k, e, fmt::format("walls[{}].x0_m", w).c_str())));
      }
    }
    if (std::holds_alternative<InjectionEffectSpec>(e) && !scene.boundary.radial) {
      return InvalidArgument(
          fmt::format("{}: injects into the well of a radial boundary; set scene.boundary.radial",
                      Field(k, e, "")));
    }
  }
  // Without contacts the particles stand still, so only the flow effect has anything to do; a
  // list without it (gravity alone, weighing a fluid that nothing moves) would run nothing.
  if (!mechanics && !flow && !scene.effects.empty()) {
    return InvalidArgument(
        "scene.effects: neither contacts nor flow is listed, so nothing would run (on a frozen "
        "packing gravity weighs the fluid of the flow effect: add effects { flow {} })");
  }
  if (mechanics) {
    if (scene.solver.kind == SolverKind::kSteady) {
      return InvalidArgument(
          "scene.solver.kind: a scene whose particles move (effect contacts) needs a transient "
          "solver (explicit or implicit), not steady");
    }
  }
  return Status::Ok();
}

}  // namespace seep::core
