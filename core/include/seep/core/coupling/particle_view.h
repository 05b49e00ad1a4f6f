// ParticleView: read-only centre and radius arrays of the disks the coupling code works on.
//
// The coupling area must not depend on the DEM's own state type, so every function here takes
// the particles as three plain arrays indexed by particle id (the ids used by the contact list
// and the DomainNetwork). A Packing converts with ViewOf(); a DEM passes its position arrays.
#pragma once

#include <cstddef>
#include <span>

#include "seep/core/geometry/packing.h"
#include "seep/core/status.h"

namespace seep::core {

struct ParticleView {
  std::span<const double> x;       // centre x, m
  std::span<const double> y;       // centre y, m
  std::span<const double> radius;  // > 0, m

  std::size_t size() const { return x.size(); }
};

inline ParticleView ViewOf(const Packing& packing) {
  return ParticleView{packing.x, packing.y, packing.radius};
}

// Cheap check (array lengths only, O(1)): "<what>: x, y and radius differ in length (3, 3, 2)".
Status CheckParticleView(const ParticleView& particles, const char* what);

}  // namespace seep::core
