// DemCounters: plain work counters of the DEM pieces, so that a test can assert that a scene pays
// nothing for an effect it does not list (every counter of an absent piece stays zero).
//
// Each piece increments only its own fields, and only when it is called; counters are integers,
// summed with integer reductions, so they are identical for any thread count.
#pragma once

#include <cstdint>

namespace seep::core {

struct DemCounters {
  // DemContactForces (contacts, walls, bonds).
  std::uint64_t neighbour_rebuilds = 0;  // Verlet list rebuilds (cell-list passes)
  std::uint64_t pair_checks = 0;         // disk-disk candidate pairs looked at (gap computed)
  std::uint64_t pair_evaluations = 0;    // disk-disk pairs in contact whose law was evaluated
  std::uint64_t wall_checks = 0;         // disk-wall candidates looked at
  std::uint64_t wall_evaluations = 0;    // disk-wall contacts whose law was evaluated
  std::uint64_t bond_evaluations = 0;    // parallel-bond updates
  std::uint64_t bonds_broken = 0;        // bonds broken since the counters were reset
  // Body forces and motion.
  std::uint64_t gravity_applications = 0;        // particle-force updates by AddGravity
  std::uint64_t local_damping_applications = 0;  // particle updates by ApplyLocalDamping
  // Loaded force and torque components ApplyLocalDamping took as at rest (left undamped;
  // dem_integrator.cc says which are loaded).
  std::uint64_t local_damping_at_rest = 0;
  std::uint64_t integrations = 0;   // particle updates by the integrator halves
  std::uint64_t servo_updates = 0;  // servo-wall velocity updates
};

}  // namespace seep::core
