// Valid random scenes across the feature space, for the tests that check laws rather than
// examples (scene_laws.h) and for the bench that runs thousands of them
// (bench/robustness/scene_laws_bench.cc).
//
// GenerateScene(seed) is a pure function of the seed: the same seed gives the same scene on any
// machine (std::mt19937_64 and the distributions below are drawn by hand, not through
// std::uniform_real_distribution, whose algorithm the standard leaves to the library). Every
// scene it returns passes ValidateScene and is small (at most about 300 particles) so that a
// fixed-seed subset runs in CTest.
//
// Families (Family below):
//   - frozen: pipe flow on a fixed packing; lattice, random or listed packing; steady, explicit,
//     implicit or Crank-Nicolson; linear (either axis, closed inlet) or radial boundary; fluid
//     weight with a hydrostatic start; a boundary region (fixed pressure or flux).
//   - box: a DEM sample in four side walls (the fluid sealed or drained through platens, a servo
//     lid on the total or the effective stress), gravity with or without fluid weight, bonds,
//     local damping, every coupling effect, re-detection.
//   - disc: a bonded disc around a well, injected or held at a pressure, without gravity.
#pragma once

#include <cstdint>
#include <string>

#include "seep/core/spec/scene_spec.h"

namespace seep::core::metamorphic {

enum class Family { kFrozen, kBox, kDisc };

struct GeneratedScene {
  SceneSpec scene;
  Family family = Family::kFrozen;
  // Steps the laws are checked over (moving scenes; a frozen transient scene runs to its end).
  std::uint64_t steps = 0;
};

struct GeneratorOptions {
  // Real water (K_f = 2.2e9 Pa) in the moving families too. Off by default: the DEM step the
  // stepper picks is not yet stable for a bonded sample filled with real water (issue 49's
  // stable step; the translation law found rounding growing on such scenes until it parted
  // them, as it does not at half the step), so the CTest suite leaves them to the bench
  // (seep_scene_laws_bench --real-water), whose failures show where the step stands.
  bool coupled_real_water = false;
};

GeneratedScene GenerateScene(std::uint64_t seed, const GeneratorOptions& options = {});

const char* FamilyName(Family family);

}  // namespace seep::core::metamorphic
