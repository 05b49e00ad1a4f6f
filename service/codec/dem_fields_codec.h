// The mechanical part of GetJobFields that core::SceneFields does not carry: the bonds, intact
// and broken, and the walls as drawable segments (seep.v1.JobFields fields 29 to 35).
//
// The DEM keeps only intact bonds: a broken bond stays in its contact table until the next
// neighbour-list rebuild drops it. Bonds are made once, at set-up (the bonds effect's Bind), so
// the bonds of a freshly created simulation of the scene are every bond the run ever had, and
// those of them not intact in a restored state are the broken ones (as many as the run's
// bonds_broken metric: each bond breaks once).
#pragma once

#include <cstdint>
#include <vector>

#include "seep/core/run/simulation.h"
#include "seep/v1/job_service.pb.h"

namespace seep::service {

// The bonds in a simulation's contact table now, sorted by (i, j) with i < j; intact[b] is 0
// for a bond that has failed but is not yet dropped. Empty for a scene without contacts.
struct BondList {
  std::vector<std::int32_t> i, j;
  std::vector<std::uint8_t> intact;
};

BondList CurrentBonds(const core::Simulation& sim);

// Fills bond_particle_i/j and bond_broken with every bond of `at_set_up` (CurrentBonds of the
// simulation as created), broken unless `sim` holds it intact, and wall_x0_m .. wall_y1_m with
// one segment per wall of `sim` (the rule is in job_service.proto).
void DemFieldsToProto(const core::Simulation& sim, const BondList& at_set_up, v1::JobFields* out);

}  // namespace seep::service
