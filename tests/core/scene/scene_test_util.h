// Helpers shared by the scene verification tests.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "seep/core/run/run_scene.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core::scene_test {

inline constexpr double kRadius = 1e-3;
inline constexpr double kAperture = 1e-5;
inline constexpr double kViscosity = 1e-3;

// A rigid lattice permeameter: F = 0 (a = a0 everywhere), steady solver.
inline SceneSpec LatticeScene(LatticeKind kind, std::uint32_t columns, std::uint32_t rows,
                              FlowAxis axis) {
  SceneSpec s;
  s.name = "lattice";
  s.packing.source = LatticePackingSpec{kind, columns, rows, kRadius};
  s.fluid.viscosity_pa_s = kViscosity;
  s.aperture.residual_aperture_m = kAperture;
  s.boundary.axis = axis;
  s.boundary.inlet_pressure_pa = 1e5;
  s.boundary.outlet_pressure_pa = 0.0;
  s.solver.kind = SolverKind::kSteady;
  return s;
}

// The seeded polydisperse packing of examples/darcy_random_packing.textproto.
inline SceneSpec RandomScene(std::uint64_t seed) {
  SceneSpec s;
  s.name = "random";
  RandomPackingSpec r;
  r.seed = seed;
  r.width_m = 0.04;
  r.height_m = 0.02;
  r.min_radius_m = 0.8e-3;
  r.max_radius_m = 1.0e-3;
  r.particle_count = 300;
  r.target_porosity = 0.2;
  s.packing.source = r;
  s.packing.contact_gap_m = 2e-5;
  s.fluid.viscosity_pa_s = kViscosity;
  s.aperture.residual_aperture_m = kAperture;
  s.aperture.reference_force_n = 1e3;
  s.aperture.gap_multiplier = 0.5;
  s.boundary.axis = FlowAxis::kX;
  s.boundary.inlet_pressure_pa = 1e5;
  s.boundary.outlet_pressure_pa = 0.0;
  s.solver.kind = SolverKind::kSteady;
  return s;
}

// The value of a named metric; fails the test if it is missing.
inline double Metric(const RunReport& report, const std::string& name) {
  for (const auto& [key, value] : report.metrics) {
    if (key == name) return value;
  }
  ADD_FAILURE() << "metric " << name << " is missing";
  return 0.0;
}

}  // namespace seep::core::scene_test
