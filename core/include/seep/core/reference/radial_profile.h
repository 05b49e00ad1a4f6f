// The pressure profile of a radial scene against the Thiem form p = A + B ln r (docs/physics.md
// §3.3): the least-squares fit over a window of radii, the effective well radius where the fit
// reaches the well pressure, and ring means that smooth out the packing's irregularity. Shared by
// the V12 verification test and the accuracy benchmark, so both compare the same way.
#pragma once

#include <cmath>
#include <vector>

#include "seep/core/network/scene_network.h"
#include "seep/core/status.h"

namespace seep::core {

struct RadialProfileFit {
  std::vector<double> ln_r;      // per windowed domain: ln of its centroid's distance from the well
  std::vector<double> pressure;  // per windowed domain: its pressure, Pa
  double slope = 0.0;            // B, Pa
  double intercept = 0.0;        // A, Pa

  // The radius at which the fit reaches the well pressure.
  double EffectiveWellRadius(double well_pressure) const {
    return std::exp((well_pressure - intercept) / slope);
  }
};

// Fits the domains (the well domain left out) whose centroid lies strictly between r_min and
// r_max from the well centre. FAILED_PRECONDITION when fewer than two distinct radii fall inside.
Result<RadialProfileFit> FitRadialProfile(const SceneNetwork& net, double r_min, double r_max);

struct RingMean {
  double ln_r = 0.0;      // mean ln r of the ring's domains
  double pressure = 0.0;  // their mean pressure, Pa
};

// The windowed domains grouped into rings of width ring_width outward from r_min (the last ring
// takes the remainder up to r_max); empty rings are left out.
std::vector<RingMean> RingMeans(const RadialProfileFit& fit, double r_min, double r_max,
                                double ring_width);

}  // namespace seep::core
