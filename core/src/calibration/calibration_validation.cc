// ValidateCalibration: the field checks of a CalibrationSpec (calibration_spec.h).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "seep/core/calibration/calibration_spec.h"

namespace seep::core {
namespace {

// Below this the steady solve's round-off (about 1e-13 relative in k) decides convergence, not
// the calibration.
constexpr double kMinTolerance = 1e-12;
constexpr int kMaxIterationsLimit = 1000;

Status ValidateScenePart(const SceneSpec& scene) {
  // a0 is the unknown: validate the rest with a placeholder that satisfies a0 <= a_max.
  SceneSpec probe = scene;
  probe.aperture.residual_aperture_m =
      scene.aperture.max_aperture_m > 0.0 ? scene.aperture.max_aperture_m : 1.0;
  if (const Status s = ValidateScene(probe); !s.ok()) {
    return Status(s.code(), "calibration." + s.message());
  }
  if (scene.boundary.radial) {
    return InvalidArgument(
        "calibration.scene.boundary.radial: must be unset; the calibration measures k with a "
        "linear permeameter along scene.boundary.axis");
  }
  if (scene.boundary.inlet_pressure_pa == scene.boundary.outlet_pressure_pa) {
    return InvalidArgument(fmt::format(
        "calibration.scene.boundary.outlet_pressure_pa: must differ from inlet_pressure_pa (both "
        "{}); the permeameter needs a pressure drop",
        scene.boundary.inlet_pressure_pa));
  }
  return Status::Ok();
}

Status ValidateStress(const CalibrationStressSpec& stress, double reference_force) {
  if (!std::isfinite(stress.uniform_normal_force_n)) {
    return InvalidArgument(
        fmt::format("calibration.stress.uniform_normal_force_n: must be finite (got {})",
                    stress.uniform_normal_force_n));
  }
  bool compressive = stress.uniform_normal_force_n > 0.0;
  std::vector<std::pair<std::pair<std::int32_t, std::int32_t>, std::size_t>> pairs;
  pairs.reserve(stress.contact_forces.size());
  for (std::size_t k = 0; k < stress.contact_forces.size(); ++k) {
    const ContactForceSpec& c = stress.contact_forces[k];
    if (c.particle_i < 0 || c.particle_j < 0 || c.particle_i == c.particle_j) {
      return InvalidArgument(fmt::format(
          "calibration.stress.contact_forces[{}]: particle ids must be two distinct ids >= 0 "
          "(got {}, {})",
          k, c.particle_i, c.particle_j));
    }
    if (!std::isfinite(c.normal_force_n)) {
      return InvalidArgument(
          fmt::format("calibration.stress.contact_forces[{}].normal_force_n: must be finite (got "
                      "{})",
                      k, c.normal_force_n));
    }
    compressive = compressive || c.normal_force_n > 0.0;
    pairs.push_back({std::minmax(c.particle_i, c.particle_j), k});
  }
  std::sort(pairs.begin(), pairs.end());
  for (std::size_t k = 1; k < pairs.size(); ++k) {
    if (pairs[k].first == pairs[k - 1].first) {
      return InvalidArgument(fmt::format(
          "calibration.stress.contact_forces[{}]: contact ({}, {}) is already listed at index {}",
          pairs[k].second, pairs[k].first.first, pairs[k].first.second, pairs[k - 1].second));
    }
  }
  if (compressive && !(reference_force > 0.0)) {
    return InvalidArgument(
        fmt::format("calibration.scene.aperture.reference_force_n: must be > 0 when contacts "
                    "carry compressive forces (got {})",
                    reference_force));
  }
  return Status::Ok();
}

}  // namespace

Status ValidateCalibration(const CalibrationSpec& spec) {
  SEEP_RETURN_IF_ERROR(ValidateScenePart(spec.scene));
  SEEP_RETURN_IF_ERROR(ValidateStress(spec.stress, spec.scene.aperture.reference_force_n));
  if (spec.target_permeabilities_m2.empty()) {
    return InvalidArgument("calibration.target_permeabilities_m2: needs at least one target");
  }
  for (std::size_t k = 0; k < spec.target_permeabilities_m2.size(); ++k) {
    const double target = spec.target_permeabilities_m2[k];
    if (!std::isfinite(target) || target <= 0.0) {
      return InvalidArgument(fmt::format(
          "calibration.target_permeabilities_m2[{}]: must be a finite number > 0 (got {})", k,
          target));
    }
  }
  if (!(spec.tolerance >= kMinTolerance && spec.tolerance < 1.0)) {
    return InvalidArgument(
        fmt::format("calibration.tolerance: must lie in [{}, 1) (got {}); below {} the solver's "
                    "round-off decides",
                    kMinTolerance, spec.tolerance, kMinTolerance));
  }
  if (spec.max_iterations < 1 || spec.max_iterations > kMaxIterationsLimit) {
    return InvalidArgument(fmt::format("calibration.max_iterations: must lie in [1, {}] (got {})",
                                       kMaxIterationsLimit, spec.max_iterations));
  }
  return Status::Ok();
}

}  // namespace seep::core
