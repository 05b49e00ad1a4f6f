#include "seep/core/coupling/buoyancy.h"

#include <numbers>

namespace seep::core {

void AddBuoyancy(const ParticleView& particles, double wx, double wy, double* fx, double* fy) {
  const double* r = particles.radius.data();
  const std::size_t n = particles.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double area = std::numbers::pi * r[i] * r[i];
    fx[i] -= wx * area;
    fy[i] -= wy * area;
  }
}

}  // namespace seep::core
