#include "codec/effect_codec.h"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>
#include <optional>
#include <utility>

namespace seep::service {
namespace {

using core::InvalidArgument;
using core::Result;

Result<core::ContactsEffectSpec> ContactsFromProto(const v1::ContactsEffect& c,
                                                   const std::string& path) {
  core::ContactsEffectSpec spec;
  const v1::ContactLaw& law = c.law();
  spec.law.kn = law.kn_n_per_m();
  spec.law.kt = law.kt_n_per_m();
  spec.law.friction = law.friction();
  switch (law.damping()) {
    case v1::NORMAL_DAMPING_PER_REDUCED_MASS:
      spec.law.damping_mode = core::NormalDampingMode::kPerReducedMass;
      break;
    case v1::NORMAL_DAMPING_CRITICAL_RATIO:
      spec.law.damping_mode = core::NormalDampingMode::kCriticalRatio;
      break;
    default:
      return InvalidArgument(
          fmt::format("{}.law.damping: must be NORMAL_DAMPING_PER_REDUCED_MASS or "
                      "NORMAL_DAMPING_CRITICAL_RATIO (got {})",
                      path, v1::NormalDamping_Name(law.damping())));
  }
  spec.law.gamma_n = law.gamma_n_per_s();
  spec.law.damping_ratio = law.damping_ratio();
  spec.density_kg_m3 = c.density_kg_m3();
  spec.skin_m = c.skin_m();
  spec.dt_safety = c.dt_safety() == 0.0 ? 0.2 : c.dt_safety();
  return spec;
}

// The end points of a wall given by them (all four set, side unset), or nullopt for a side wall.
Result<std::optional<core::WallSegmentSpec>> SegmentFromProto(const v1::Wall& wall,
                                                              const std::string& path) {
  const std::pair<const char*, bool> given[] = {{"x0_m", wall.has_x0_m()},
                                                {"y0_m", wall.has_y0_m()},
                                                {"x1_m", wall.has_x1_m()},
                                                {"y1_m", wall.has_y1_m()}};
  const auto count =
      std::count_if(std::begin(given), std::end(given), [](const auto& g) { return g.second; });
  if (count == 0) return std::optional<core::WallSegmentSpec>();
  for (const auto& [name, set] : given) {
    if (!set) {
      return InvalidArgument(fmt::format(
          "{}.{}: a wall given by its end points needs all four of x0_m, y0_m, x1_m, y1_m", path,
          name));
    }
  }
  if (wall.side() != v1::WALL_SIDE_UNSPECIFIED) {
    return InvalidArgument(fmt::format(
        "{}.side: a wall is given by its side or by its end points, not both (got {} and "
        "x0_m..y1_m)",
        path, v1::WallSide_Name(wall.side())));
  }
  return std::optional<core::WallSegmentSpec>(
      core::WallSegmentSpec{wall.x0_m(), wall.y0_m(), wall.x1_m(), wall.y1_m()});
}

Result<core::WallsEffectSpec> WallsFromProto(const v1::WallsEffect& w, const std::string& path) {
  core::WallsEffectSpec spec;
  for (int k = 0; k < w.walls_size(); ++k) {
    const v1::Wall& wall = w.walls(k);
    core::WallSpec out;
    SEEP_ASSIGN_OR_RETURN(out.segment,
                          SegmentFromProto(wall, fmt::format("{}.walls[{}]", path, k)));
    if (wall.has_normal_velocity_m_s()) out.normal_velocity_m_s = wall.normal_velocity_m_s();
    // A segment wall has no side (SegmentFromProto checked it is unset).
    if (!out.segment) {
      switch (wall.side()) {
        case v1::WALL_SIDE_LEFT:
          out.side = core::WallSide::kLeft;
          break;
        case v1::WALL_SIDE_RIGHT:
          out.side = core::WallSide::kRight;
          break;
        case v1::WALL_SIDE_BOTTOM:
          out.side = core::WallSide::kBottom;
          break;
        case v1::WALL_SIDE_TOP:
          out.side = core::WallSide::kTop;
          break;
        default:
          return InvalidArgument(fmt::format(
              "{}.walls[{}].side: must be WALL_SIDE_LEFT, WALL_SIDE_RIGHT, WALL_SIDE_BOTTOM or "
              "WALL_SIDE_TOP, or leave it unset and give the end points x0_m, y0_m, x1_m, y1_m "
              "(got {})",
              path, k, v1::WallSide_Name(wall.side())));
      }
    }
    out.servo_stress_pa = wall.servo_stress_pa();
    out.servo_gain_fraction = wall.servo_gain_fraction() == 0.0 ? 0.5 : wall.servo_gain_fraction();
    out.servo_max_speed_m_s = wall.servo_max_speed_m_s();
    out.servo_effective_stress = wall.servo_effective_stress();
    if (wall.has_drain()) {
      core::WallDrainSpec drain;
      if (wall.drain().has_pressure_pa()) drain.pressure_pa = wall.drain().pressure_pa();
      drain.conductance_m_per_pa_s = wall.drain().conductance_m_per_pa_s();
      out.drain = drain;
    }
    spec.walls.push_back(out);
  }
  return spec;
}

}  // namespace

core::Status AppendEffectFromProto(const v1::Effect& effect, std::size_t index,
                                   std::vector<core::EffectSpec>* out) {
  const auto path = [&](const char* name) {
    return fmt::format("scene.effects[{}].{}", index, name);
  };
  switch (effect.kind_case()) {
    case v1::Effect::kContacts: {
      SEEP_ASSIGN_OR_RETURN(core::ContactsEffectSpec spec,
                            ContactsFromProto(effect.contacts(), path("contacts")));
      out->emplace_back(spec);
      return core::Status::Ok();
    }
    case v1::Effect::kBonds: {
      const v1::BondsEffect& b = effect.bonds();
      core::BondsEffectSpec spec;
      spec.params.normal_stiffness = b.normal_stiffness_pa_per_m();
      spec.params.shear_stiffness = b.shear_stiffness_pa_per_m();
      spec.params.radius_multiplier = b.radius_multiplier() == 0.0 ? 1.0 : b.radius_multiplier();
      spec.params.tensile_strength = b.tensile_strength_pa();
      spec.params.shear_strength = b.shear_strength_pa();
      spec.tolerance_m = b.tolerance_m();
      out->emplace_back(spec);
      return core::Status::Ok();
    }
    case v1::Effect::kGravity:
      out->emplace_back(
          core::GravityEffectSpec{effect.gravity().gx_m_s2(), effect.gravity().gy_m_s2()});
      return core::Status::Ok();
    case v1::Effect::kFluidForces:
      out->emplace_back(core::FluidForcesEffectSpec{});
      return core::Status::Ok();
    case v1::Effect::kLocalDamping:
      out->emplace_back(core::LocalDampingEffectSpec{effect.local_damping().alpha()});
      return core::Status::Ok();
    case v1::Effect::kWalls: {
      SEEP_ASSIGN_OR_RETURN(core::WallsEffectSpec spec,
                            WallsFromProto(effect.walls(), path("walls")));
      out->emplace_back(std::move(spec));
      return core::Status::Ok();
    }
    case v1::Effect::kVolumeChange:
      out->emplace_back(core::VolumeChangeEffectSpec{});
      return core::Status::Ok();
    case v1::Effect::kApertureUpdate:
      out->emplace_back(core::ApertureUpdateEffectSpec{});
      return core::Status::Ok();
    case v1::Effect::kFlow:
      out->emplace_back(core::FlowEffectSpec{effect.flow().every_steps()});
      return core::Status::Ok();
    case v1::Effect::kRedetection:
      out->emplace_back(core::RedetectionEffectSpec{});
      return core::Status::Ok();
    case v1::Effect::kInjection:
      out->emplace_back(core::InjectionEffectSpec{effect.injection().rate_m2_s()});
      return core::Status::Ok();
    case v1::Effect::KIND_NOT_SET:
      break;
  }
  return InvalidArgument(fmt::format(
      "scene.effects[{}]: names no effect (set one of contacts, bonds, gravity, fluid_forces, "
      "local_damping, walls, volume_change, aperture_update, flow, redetection, injection)",
      index));
}

}  // namespace seep::service
