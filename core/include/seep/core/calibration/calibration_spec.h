// CalibrationSpec: what a residual-aperture calibration needs (docs/physics.md §1.3, issue #6).
//
// A calibration finds the residual aperture a0 of the aperture law (seed eqs. 2-3) that makes a
// steady permeameter on a given packing, fluid and stress state measure a target permeability k.
// The packing, fluid, aperture law (F0, m, a_max) and the linear boundary (flow axis, inlet and
// outlet pressures) come from an ordinary SceneSpec; the flow direction of the calibration is the
// scene's axial boundary. The contact forces that the scene runner does not have (it builds an
// unloaded packing, F = 0) come from CalibrationStressSpec. Plain C++ values, SI units, per unit
// thickness, so the service can fill them from its own messages.
#pragma once

#include <cstdint>
#include <vector>

#include "seep/core/spec/scene_spec.h"
#include "seep/core/status.h"

namespace seep::core {

// The normal force on one contact, named by its two particles (ids into the packing the scene
// builds; either order). Positive = compressive, so its pipe has a = a0 F0 / (F + F0).
struct ContactForceSpec {
  std::int32_t particle_i = -1;
  std::int32_t particle_j = -1;
  double normal_force_n = 0.0;  // N per m of thickness
};

// The stress state the aperture law sees during calibration. A contact not listed carries
// uniform_normal_force_n. All zero (the default) is the unloaded packing of BuildSceneNetwork:
// a = a0 + m g on every pipe.
struct CalibrationStressSpec {
  double uniform_normal_force_n = 0.0;
  std::vector<ContactForceSpec> contact_forces;
};

struct CalibrationSpec {
  // Packing, fluid, aperture law and linear boundary. scene.aperture.residual_aperture_m is
  // ignored (it is the result); scene.solver is ignored (the permeameter is always steady);
  // scene.boundary.radial must be unset and the inlet and outlet pressures must differ.
  SceneSpec scene;
  CalibrationStressSpec stress;
  // One calibration per entry (a sweep when several), each independent of the others.
  std::vector<double> target_permeabilities_m2;
  // Converged when |k - k_target| / k_target < tolerance.
  double tolerance = 1e-6;
  // Permeameter solves allowed per target (the first guess counts as one).
  int max_iterations = 30;
};

// Checks the spec without building the packing. The first violation is returned with its field
// path, e.g. "calibration.target_permeabilities_m2[2]: must be a finite number > 0 (got -1)" or
// "calibration.scene.fluid.viscosity_pa_s: ...". Particle ids of contact_forces are checked
// against the built packing by Calibrator::Create.
Status ValidateCalibration(const CalibrationSpec& spec);

}  // namespace seep::core
