// Building the DEM particle state from a packing, and its bookkeeping.
#include "seep/core/dem/dem_particles.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "dem_parallel.h"

namespace seep::core {

void DemParticles::ClearForces() {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(size());
  dem_internal::ForEachShare(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    std::fill(fx.begin() + begin, fx.begin() + end, 0.0);
    std::fill(fy.begin() + begin, fy.begin() + end, 0.0);
    std::fill(torque.begin() + begin, torque.begin() + end, 0.0);
  });
}

std::size_t DemParticles::MemoryBytes() const {
  std::size_t b = 0;
  for (const std::vector<double>* v : {&x, &y, &vx, &vy, &omega, &fx, &fy, &torque, &radius, &mass,
                                       &inv_mass, &inertia, &inv_inertia}) {
    b += v->capacity() * sizeof(double);
  }
  return b + fixed.capacity();
}

void SetDiskMass(DemParticles* particles, std::size_t i, double density) {
  const double r = particles->radius[i];
  const double m = density * std::numbers::pi * r * r;
  const double inertia = 0.5 * m * r * r;
  particles->mass[i] = m;
  particles->inv_mass[i] = 1.0 / m;
  particles->inertia[i] = inertia;
  particles->inv_inertia[i] = 1.0 / inertia;
}

Result<DemParticles> MakeDemParticles(const Packing& packing, double density) {
  if (!std::isfinite(density) || density <= 0.0) {
    return InvalidArgument("dem.density: must be finite and > 0 (got " + std::to_string(density) +
                           ")");
  }
  SEEP_RETURN_IF_ERROR(ValidatePacking(packing));
  const std::size_t n = packing.size();
  DemParticles p;
  p.x = packing.x;
  p.y = packing.y;
  p.radius = packing.radius;
  for (std::vector<double>* v : {&p.vx, &p.vy, &p.omega, &p.fx, &p.fy, &p.torque, &p.mass,
                                 &p.inv_mass, &p.inertia, &p.inv_inertia}) {
    v->assign(n, 0.0);
  }
  p.fixed.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) SetDiskMass(&p, i, density);
  return p;
}

double KineticEnergy(const DemParticles& p) {
  double kinetic = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    kinetic += 0.5 * p.mass[i] * (p.vx[i] * p.vx[i] + p.vy[i] * p.vy[i]) +
               0.5 * p.inertia[i] * p.omega[i] * p.omega[i];
  }
  return kinetic;
}

}  // namespace seep::core
