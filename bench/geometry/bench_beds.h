// The packings the geometry benches share: the hex lattice with jittered centres (irregular
// angles, about half the contacts overlapping) and the settled bed's mean radius.
#pragma once

#include <cstddef>
#include <random>

#include "seep/core/geometry/packing.h"
#include "seep/core/geometry/random_packing.h"

namespace seep::bench {

// `hex` with every centre moved by up to 2 % of its radius R in x and in y (seed 7).
inline core::Packing JitteredHexLattice(const core::Packing& hex, double R) {
  core::Packing jittered = hex;
  std::mt19937_64 rng(7);
  for (std::size_t k = 0; k < jittered.size(); ++k) {
    jittered.x[k] += 0.02 * R * (2 * core::UniformUnit(rng()) - 1);
    jittered.y[k] += 0.02 * R * (2 * core::UniformUnit(rng()) - 1);
  }
  return jittered;
}

inline double MeanRadius(const core::Packing& packing) {
  double sum = 0.0;
  for (const double r : packing.radius) sum += r;
  return sum / static_cast<double>(packing.size());
}

}  // namespace seep::bench
