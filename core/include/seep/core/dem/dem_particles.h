// DemParticles: the dynamic state of the DEM disks, one array per field (structure of arrays).
//
// A particle's id is its index, the same id as in the Packing it was built from, so contacts,
// domains and pipes of the geometry area keep referring to the same disks. Units are whatever
// the packing and density use (SI or reduced); 2D with unit out-of-plane thickness:
//   mass    m = density * pi * R^2        (per unit thickness)
//   inertia I = m R^2 / 2                 (solid disk about its centre)
// `fixed` particles keep their velocity (and spin): forces are still computed on them (so the
// reaction can be read) but the integrator does not change vx, vy, omega; their position still
// advances with the held velocity, which is how a test or a scene prescribes a motion.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "seep/core/geometry/packing.h"
#include "seep/core/status.h"

namespace seep::core {

struct DemParticles {
  std::vector<double> x, y;         // centre
  std::vector<double> vx, vy;       // velocity
  std::vector<double> omega;        // spin (counter-clockwise positive)
  std::vector<double> fx, fy;       // force accumulated in the current step
  std::vector<double> torque;       // torque accumulated in the current step
  std::vector<double> radius;       // > 0
  std::vector<double> mass;         // > 0
  std::vector<double> inv_mass;     // 1 / mass (the integrator multiplies, never divides)
  std::vector<double> inertia;      // > 0
  std::vector<double> inv_inertia;  // 1 / inertia
  std::vector<std::uint8_t> fixed;  // 1 = velocity and spin held

  std::size_t size() const { return x.size(); }
  // Zeroes fx, fy, torque (the first thing of every force pass).
  void ClearForces();
  // Heap bytes held by the arrays (capacity), for memory reports.
  std::size_t MemoryBytes() const;
  // Bytes of state per particle (sum of the element sizes of all arrays).
  static constexpr std::size_t kBytesPerParticle = 14 * sizeof(double) + sizeof(std::uint8_t);
};

// Disks at rest at the packing's positions. density must be finite and > 0 (mass per unit area).
Result<DemParticles> MakeDemParticles(const Packing& packing, double density);

// Sets the mass and inertia of particle i from its radius and a density (used by the builder and
// by tests that change one disk).
void SetDiskMass(DemParticles* particles, std::size_t i, double density);

// The disks' kinetic energy, translation and rotation, J per m of thickness.
double KineticEnergy(const DemParticles& particles);

}  // namespace seep::core
