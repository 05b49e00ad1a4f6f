// Scenes shared by the calibration tests: a steady permeameter along x on a lattice or on the
// seeded random packing of the V06 scene test, and contact forces drawn for every contact.
#pragma once

#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "seep/core/calibration/calibration_spec.h"
#include "seep/core/geometry/random_packing.h"
#include "seep/core/network/scene_network.h"

namespace seep::core::calibration_test {

constexpr double kViscosity = 1e-3;
constexpr double kPressureDrop = 1e5;
constexpr double kReferenceForce = 10.0;  // F0, N per m

inline CalibrationSpec PermeameterSpec(PackingSource source) {
  CalibrationSpec spec;
  spec.scene.packing.source = std::move(source);
  spec.scene.fluid = {kViscosity, 2.2e9};
  spec.scene.aperture = {0.0, kReferenceForce, 0.0, 0.0};
  spec.scene.boundary.axis = FlowAxis::kX;
  spec.scene.boundary.inlet_pressure_pa = kPressureDrop;
  spec.scene.boundary.outlet_pressure_pa = 0.0;
  return spec;
}

// 400 disks of radius 0.8-1 mm (before the growth to the target) in a 40 x 20 mm box at 2D box
// porosity 0.2, contacts up to 20 um apart: the V06 scene test's packing. Generated once and
// passed as a particle list, so that each test pays only for contact and domain detection.
inline CalibrationSpec RandomPackingSpec400() {
  static const ParticleListSpec particles = [] {
    RandomPackingSpec random;
    random.seed = 11;
    random.width_m = 0.04;
    random.height_m = 0.02;
    random.min_radius_m = 0.8e-3;
    random.max_radius_m = 1.0e-3;
    random.particle_count = 400;
    random.target_porosity = 0.2;
    PackingSpec packing;
    packing.source = random;
    auto built = BuildScenePacking(packing);
    ParticleListSpec list;
    if (built.ok()) list = {built->x, built->y, built->radius};
    return list;
  }();
  CalibrationSpec spec = PermeameterSpec(particles);
  spec.scene.packing.contact_gap_m = 2e-5;
  return spec;
}

// The contacts the calibration will see (same scene, same detection).
inline ContactList SceneContacts(const CalibrationSpec& spec) {
  SceneSpec scene = spec.scene;
  scene.aperture.residual_aperture_m = 1e-5;
  auto net = BuildSceneNetwork(scene);
  return net.ok() ? net->contacts : ContactList{};
}

// Compressive forces uniform in [0.2, 1.2] F0 on every contact, seeded (as the V06 scene test).
inline std::vector<ContactForceSpec> CompressiveForces(const ContactList& contacts) {
  std::mt19937_64 rng(2024);
  std::vector<ContactForceSpec> forces;
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    forces.push_back({contacts.i[c], contacts.j[c], kReferenceForce * (0.2 + UniformUnit(rng()))});
  }
  return forces;
}

}  // namespace seep::core::calibration_test
