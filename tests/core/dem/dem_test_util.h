// Small builders shared by the DEM tests: disks from a list, a contact model, a stepping loop.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <initializer_list>
#include <vector>

#include "seep/core/dem/dem_contacts.h"
#include "seep/core/dem/dem_particles.h"
#include "seep/core/dem/dem_step.h"
#include "seep/core/dem/servo_wall.h"
#include "seep/core/geometry/packing.h"

namespace seep::core::dem_test {

struct Disk {
  double x, y, r;
};

inline DemParticles MakeDisks(std::initializer_list<Disk> disks, double density) {
  Packing packing;
  for (const Disk& d : disks) packing.Add(d.x, d.y, d.r);
  Result<DemParticles> p = MakeDemParticles(packing, density);
  EXPECT_TRUE(p.ok()) << p.status().ToString();
  return std::move(p).value();
}

inline DemContactForces MakeContacts(const DemContactSettings& settings) {
  Result<DemContactForces> c = DemContactForces::Create(settings);
  EXPECT_TRUE(c.ok()) << c.status().ToString();
  return std::move(c).value();
}

// One force pass, then `steps` steps of dt, wall `servo_wall` servo-controlled by `servo` from
// the load of the pass before each step.
inline void RunWithServo(DemParticles* p, std::vector<DemWall>* walls, DemContactForces* contacts,
                         const ServoWallSettings& servo, std::size_t servo_wall, double dt,
                         int steps, DemCounters* counters) {
  DemStepOptions options;
  options.dt = dt;
  ASSERT_TRUE(ComputeDemForces(p, *walls, contacts, options, counters).ok());
  for (int s = 0; s < steps; ++s) {
    ApplyServo(servo, contacts->wall_loads()[servo_wall], dt, &(*walls)[servo_wall], counters);
    ASSERT_TRUE(DemStep(p, walls, contacts, options, counters).ok());
  }
}

// Whether two arrays hold the same bits (NaNs and signed zeros included).
inline bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

}  // namespace seep::core::dem_test
