// Seeded polydisperse random packing in a rectangular box, made by radius expansion.
//
// Method: `count` centres are drawn uniformly in [0, width] x [0, height] and each particle gets a
// base radius uniform in [radius_min, radius_max]. All radii are then multiplied by one common
// factor s that grows in small steps; after each step a deterministic overlap-removal iteration
// (Jacobi: every overlapping pair is pushed apart along its line of centres, shares weighted by
// the other disk's area, then disks are clamped inside the box) runs until the largest overlap is
// below `overlap_tolerance * mean radius`. So radius_min/radius_max fix the *shape* of the size
// distribution; the final radii are uniform in [s*radius_min, s*radius_max] (s is reported).
//
// Targets (exactly one):
//   - porosity n: s is set so that 1 - sum(pi r^2)/(width*height) = n exactly; the porosity that
//     counts overlap lenses once is reported (it differs by the tiny overlaps only). 2D random
//     packings jam near n ~ 0.16, so n must be larger than that to converge.
//   - coordination number Z = 2 * (pairs with gap <= contact_gap_ratio * mean radius) / count
//     (particle-particle contacts, rattlers included in count): s grows until Z reaches the
//     target, then is bisected between the last state below and the first above.
//
// Determinism: std::mt19937_64 seeded with `seed`, mapped to [0, 1) by taking its top 53 bits
// (not std::uniform_real_distribution, whose output differs between standard libraries), and a
// fixed iteration order everywhere, so the same options give bit-identical packings.
#pragma once

#include <cstdint>

#include "seep/core/geometry/packing.h"
#include "seep/core/status.h"

namespace seep::core {

struct RandomPackingOptions {
  std::int32_t count = 1000;
  double radius_min = 0.8;
  double radius_max = 1.0;
  double width = 60.0;
  double height = 60.0;
  std::uint64_t seed = 1;

  enum class Target { kPorosity, kCoordination };
  Target target = Target::kPorosity;
  double porosity = 0.25;                     // used when target == kPorosity
  double coordination = 3.0;                  // used when target == kCoordination
  double contact_gap_ratio = 1e-2;            // contact test for Z, relative to the mean radius
  double overlap_tolerance = 1e-3;            // final max overlap, relative to the mean radius
  std::int32_t max_relax_iterations = 20000;  // per growth step
};

struct RandomPacking {
  Packing packing;
  double radius_scale = 0.0;  // s: final radius = s * base radius
  double porosity = 0.0;      // 1 - (sum of disk areas - overlap lenses) / box area
  double coordination = 0.0;  // Z as defined above
  double max_overlap = 0.0;   // largest pair or wall overlap, absolute length
  double mean_radius = 0.0;
};

// InvalidArgument for bad options; FailedPrecondition when the overlaps cannot be removed (target
// too dense) or the coordination target is not reached before jamming.
Result<RandomPacking> GenerateRandomPacking(const RandomPackingOptions& options);

// The uniform [0, 1) mapping used above (top 53 bits of one 64-bit draw), exposed for tests.
double UniformUnit(std::uint64_t bits);

}  // namespace seep::core
