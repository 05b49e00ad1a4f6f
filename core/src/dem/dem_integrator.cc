// Gravity, PFC local damping, velocity-Verlet halves and the stable step estimate.
#include "seep/core/dem/dem_integrator.h"

#include <cmath>
#include <limits>
#include <string>

#include "dem_parallel.h"

namespace seep::core {

// The loops over particles below run per share of the particles (dem_internal::ForEachShare):
// on a team, or, on one thread or for a small scene, on the calling thread with no team at all.
namespace {

void GravityRange(std::ptrdiff_t begin, std::ptrdiff_t end, double gx, double gy,
                  const double* __restrict m, double* __restrict fx, double* __restrict fy) {
  for (std::ptrdiff_t i = begin; i < end; ++i) {
    fx[i] += m[i] * gx;
    fy[i] += m[i] * gy;
  }
}

// -alpha |f| sign(v), with sign(v) = 0 at rest: for |v| at most kRestFraction of the velocity
// the force gives in one step, |f| dt / m (`step_gain` = dt / m or dt / I). Counts in *at_rest
// the loaded components taken as at rest (the force's one-step velocity above `loaded_speed`):
// the side of the threshold a rounding can change, where it matters.
inline double Damped(double f, double v, double alpha, double step_gain, double loaded_speed,
                     double* at_rest) {
  const double magnitude = std::abs(f);
  if (std::abs(v) <= kRestFraction * magnitude * step_gain) {
    *at_rest += magnitude * step_gain > loaded_speed ? 1.0 : 0.0;
    return f;
  }
  const double d = alpha * magnitude;
  return v > 0.0 ? f - d : f + d;
}

// A force is loaded, for the count of components at rest, when it moves its particle by more than
// this fraction of its radius (a torque: of a radian) in one step: below it, the force is the
// rounding of balanced contact forces (a lattice's symmetric disks: 1e-16 of them) and damped or
// not changes nothing a law can see.
constexpr double kLoadedFraction = 1e-12;

// Returns the count of loaded components at rest.
double DampingRange(std::ptrdiff_t begin, std::ptrdiff_t end, double alpha, double dt,
                    double* __restrict fx, double* __restrict fy, double* __restrict torque,
                    const double* __restrict vx, const double* __restrict vy,
                    const double* __restrict omega, const double* __restrict inv_mass,
                    const double* __restrict inv_inertia, const double* __restrict radius) {
  double at_rest = 0.0;
  const double loaded_spin = kLoadedFraction / dt;  // also the loaded speed per m of radius
  for (std::ptrdiff_t i = begin; i < end; ++i) {
    const double translation = dt * inv_mass[i];
    const double loaded_speed = loaded_spin * radius[i];
    fx[i] = Damped(fx[i], vx[i], alpha, translation, loaded_speed, &at_rest);
    fy[i] = Damped(fy[i], vy[i], alpha, translation, loaded_speed, &at_rest);
    torque[i] = Damped(torque[i], omega[i], alpha, dt * inv_inertia[i], loaded_spin, &at_rest);
  }
  return at_rest;
}

}  // namespace

void AddGravity(DemParticles* p, double gx, double gy, DemCounters* counters) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(p->size());
  dem_internal::ForEachShare(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    GravityRange(begin, end, gx, gy, p->mass.data(), p->fx.data(), p->fy.data());
  });
  if (counters != nullptr) counters->gravity_applications += static_cast<std::uint64_t>(n);
}

void ApplyLocalDamping(DemParticles* p, double alpha, double dt, DemCounters* counters) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(p->size());
  const double at_rest =
      dem_internal::SumOverShares(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
        return DampingRange(begin, end, alpha, dt, p->fx.data(), p->fy.data(), p->torque.data(),
                            p->vx.data(), p->vy.data(), p->omega.data(), p->inv_mass.data(),
                            p->inv_inertia.data(), p->radius.data());
      });
  if (counters != nullptr) {
    counters->local_damping_applications += static_cast<std::uint64_t>(n);
    counters->local_damping_at_rest += static_cast<std::uint64_t>(at_rest);
  }
}

namespace {

// A velocity-Verlet half kick over [begin, end) (fixed particles keep their velocities), and with
// `drift` the drift of the positions by the new velocities.
template <bool kDrift>
void HalfStepRange(std::ptrdiff_t begin, std::ptrdiff_t end, double dt, DemParticles* p) {
  const double h = 0.5 * dt;
  double* __restrict x = p->x.data();
  double* __restrict y = p->y.data();
  double* __restrict vx = p->vx.data();
  double* __restrict vy = p->vy.data();
  double* __restrict w = p->omega.data();
  const double* __restrict fx = p->fx.data();
  const double* __restrict fy = p->fy.data();
  const double* __restrict t = p->torque.data();
  const double* __restrict im = p->inv_mass.data();
  const double* __restrict ii = p->inv_inertia.data();
  const std::uint8_t* __restrict fixed = p->fixed.data();
  for (std::ptrdiff_t i = begin; i < end; ++i) {
    if (!fixed[i]) {
      vx[i] += h * fx[i] * im[i];
      vy[i] += h * fy[i] * im[i];
      w[i] += h * t[i] * ii[i];
    }
    if constexpr (kDrift) {
      x[i] += dt * vx[i];
      y[i] += dt * vy[i];
    }
  }
}

}  // namespace

void IntegrateFirstHalf(DemParticles* p, double dt, DemCounters* counters) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(p->size());
  dem_internal::ForEachShare(
      n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) { HalfStepRange<true>(begin, end, dt, p); });
  if (counters != nullptr) counters->integrations += static_cast<std::uint64_t>(n);
}

void IntegrateSecondHalf(DemParticles* p, double dt, DemCounters* counters) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(p->size());
  dem_internal::ForEachShare(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    HalfStepRange<false>(begin, end, dt, p);
  });
  if (counters != nullptr) counters->integrations += static_cast<std::uint64_t>(n);
}

Result<double> EstimateStableTimeStep(const DemParticles& p, double kn, double kt, double safety,
                                      const BondParams* bonds) {
  if (!std::isfinite(kn) || kn <= 0.0) {
    return InvalidArgument("dem.stable_step.kn: must be finite and > 0 (got " + std::to_string(kn) +
                           ")");
  }
  if (!std::isfinite(kt) || kt < 0.0) {
    return InvalidArgument("dem.stable_step.kt: must be finite and >= 0 (got " +
                           std::to_string(kt) + ")");
  }
  if (!(safety > 0.0 && safety <= 2.0)) {
    return InvalidArgument("dem.stable_step.safety: must be in (0, 2] (got " +
                           std::to_string(safety) + ")");
  }
  if (p.size() == 0) return InvalidArgument("dem.stable_step: no particles");
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double r = p.radius[i];
    double normal = kn;
    double rotation = kt * r * r;
    if (bonds != nullptr) {
      const double area = 2.0 * bonds->radius_multiplier * r;
      normal += bonds->normal_stiffness * area;
      rotation += bonds->shear_stiffness * area * r * r +
                  bonds->normal_stiffness * area * area * area / 12.0;
    }
    best = std::min(best, std::sqrt(p.mass[i] / normal));
    if (rotation > 0.0) best = std::min(best, std::sqrt(p.inertia[i] / rotation));
  }
  return safety * best;
}

}  // namespace seep::core
