// DemContactState: everything a DemContactForces carries from one force pass to the next, as plain
// arrays and scalars, so that a run can be checkpointed and resumed bit-identically
// (DemContactForces::SaveState / RestoreState). The codec turns it into bytes; core never does.
//
// What is in it, and why each piece matters for later steps:
//   - the pair table (neighbour list, sorted by (i, j), i < j): which pairs are evaluated, their
//     shear history, the bond they carry, the viscous coefficient, and the force and gap of the
//     last evaluation (carried over at rebuilds and reported by CollectContacts);
//   - the bonds (sorted by (i, j)) with their incremental forces, failure and whether the break
//     was reported (broken bonds stay until the next rebuild drops them), and the bond parameters;
//   - the disk-wall contacts (sorted by (particle, wall)) with their shear history;
//   - the per-wall loads of the last pass (a servo reads them before the next pass);
//   - the positions of the last rebuild (particles and walls), which decide when the next rebuild
//     happens, and whether one is already pending.
// What is NOT in it: scratch buffers (cell grid, candidates, per-pair slots, packed disks) and the
// per-particle gather lists, which RestoreState re-derives from the pair table; broken_bonds(),
// the event list of the last pass (empty after a restore: the caller handles it before saving);
// the settings (the restoring object is created with the same DemContactSettings).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "seep/core/status.h"

namespace seep::core {

struct DemContactState {
  // True when the next force pass rebuilds the neighbour list whatever the displacements.
  bool needs_rebuild = true;

  // Bond parameters (BondParams), one set for the whole assembly; all zero while never bonded.
  double bond_normal_stiffness = 0.0;
  double bond_shear_stiffness = 0.0;
  double bond_radius_multiplier = 1.0;
  double bond_tensile_strength = 0.0;
  double bond_shear_strength = 0.0;

  // Pair table, one entry per neighbour-list pair, sorted strictly by (i, j) with i < j.
  std::vector<std::int32_t> pair_i, pair_j;
  std::vector<std::int32_t> pair_bond;  // index into the bond arrays, or -1
  std::vector<double> pair_damping;     // normal viscous coefficient c (>= 0)
  std::vector<double> pair_shear;       // tangential spring force (history)
  std::vector<double> pair_fn;          // normal force of the last evaluation
  std::vector<double> pair_gap;         // gap of the last evaluation

  // Bonds, sorted strictly by (i, j) with i < j.
  std::vector<std::int32_t> bond_i, bond_j;
  std::vector<double> bond_half_width;                // > 0
  std::vector<double> bond_fn, bond_fs, bond_moment;  // BondState
  std::vector<std::uint8_t> bond_failure;             // BondFailure: 0 none, 1 tension, 2 shear
  std::vector<std::uint8_t> bond_reported;            // 1 once reported in broken_bonds()

  // Disk-wall contacts, sorted strictly by (particle, wall).
  std::vector<std::int32_t> wall_contact_particle, wall_contact_wall;
  std::vector<double> wall_contact_shear, wall_contact_fn, wall_contact_gap;

  // Per wall: the loads of the last force pass (DemWallLoad); empty before the first pass.
  std::vector<double> wall_load_normal_force, wall_load_stiffness_sum, wall_load_damping_sum;
  std::vector<std::int32_t> wall_load_contact_count;

  // Positions at the last rebuild: one per particle and one per wall (both may be empty only
  // while needs_rebuild, i.e. before the first force pass).
  std::vector<double> ref_x, ref_y;
  std::vector<double> ref_wall_x, ref_wall_y;
};

// Checks that `state` can belong to a DemContactForces driving `particle_count` disks and
// `wall_count` walls: array lengths agree, ids in range, keys sorted strictly with i < j, every
// pair's bond has the pair's key, flags valid, values finite. Returns DataLoss naming the field
// and the element ("dem_state.pair_shear[3]: not finite").
Status ValidateDemContactState(const DemContactState& state, std::size_t particle_count,
                               std::size_t wall_count);

}  // namespace seep::core
