// Networks for the stability suite: permeameters (Dirichlet columns) on the lattices of
// flow_test_networks.h, seeded heterogeneous lattices, and the seeded random networks of the
// property tests (random sizes, volumes over six decades, apertures over two, random roles).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "flow_test_networks.h"
#include "seep/core/flow/flow_network.h"

namespace seep::core::stability {

// Holds column 0 at p_in and column mx-1 at p_out (the rest keep their pressure).
inline void MakePermeameter(FlowNetworkData& d, int mx, int my, double p_in, double p_out) {
  for (int j = 0; j < my; ++j) {
    d.role[j * mx] = DomainRole::kFixedPressure;
    d.pressure[j * mx] = p_in;
    d.role[j * mx + mx - 1] = DomainRole::kFixedPressure;
    d.pressure[j * mx + mx - 1] = p_out;
  }
}

// A square-lattice permeameter whose pore volumes and apertures are scaled by seeded factors
// log-uniform in [1/spread, spread]: not uniform, so no symmetry hides an error.
inline FlowNetwork MakeHeterogeneousLattice(int mx, int my, const testing::LatticeParams& lp,
                                            double spread, std::uint64_t seed, double p_in,
                                            double p_out) {
  FlowNetworkData d = testing::MakeSquareLatticeData(mx, my, lp);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (std::size_t i = 0; i < d.pore_volume.size(); ++i) {
    const double f = std::pow(spread, unit(rng));
    d.pore_volume[i] *= f;
    d.apparent_volume[i] *= f;
  }
  for (std::size_t p = 0; p < d.pipe_aperture.size(); ++p) {
    d.pipe_aperture[p] *= std::pow(spread, unit(rng));
    const double a = d.pipe_aperture[p];
    d.pipe_conductance[p] = a * a * a / (12.0 * lp.viscosity * d.pipe_length[p]);
  }
  MakePermeameter(d, mx, my, p_in, p_out);
  return testing::MakeOrDie(std::move(d));
}

// The property-test networks. Pore volumes V0 * 10^U(-3, 3), apertures a0 * 10^U(-1, 1) (any two
// differ by up to 1e2, conductances by up to 1e6), 2..40 domains joined by a random spanning tree
// plus random chords; a quarter of the networks fall apart into two components. Roles: 15% fixed
// at U(0, 1e6) Pa, 10% sources of +-U(0, 1) x 1e-9 m^2/s (when allowed), the rest free; initial
// pressures U(0, 1e6) Pa.
struct RandomNetworkShape {
  double volume_decades = 3.0;    // volumes span 10^-d .. 10^d around V0
  double aperture_decades = 1.0;  // apertures span 10^-d .. 10^d around a0
  bool allow_sources = true;
};

inline constexpr double kRandomBaseVolume = 1e-7;    // V0, m^2
inline constexpr double kRandomBaseAperture = 1e-5;  // a0, m
inline constexpr double kRandomPipeLength = 2e-3;    // L, m
inline constexpr double kRandomViscosity = 1e-3;     // mu, Pa s
inline constexpr double kRandomSourceRate = 1e-9;    // m^2/s
inline constexpr double kRandomMaxPressure = 1e6;    // Pa

inline FlowNetwork MakeRandomNetwork(std::uint64_t seed, const RandomNetworkShape& shape = {}) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int n = 2 + static_cast<int>(unit(rng) * 39.0);
  FlowNetworkData d;
  for (int i = 0; i < n; ++i) {
    const double vp =
        kRandomBaseVolume * std::pow(10.0, shape.volume_decades * (2 * unit(rng) - 1));
    DomainRole role = DomainRole::kFree;
    const double r = unit(rng);
    if (r < 0.15) {
      role = DomainRole::kFixedPressure;
    } else if (shape.allow_sources && r < 0.25) {
      role = DomainRole::kSource;
    }
    testing::AddDomain(d, 2.0 * vp, vp, kRandomMaxPressure * unit(rng), role);
    if (role == DomainRole::kSource) d.source_rate.back() = kRandomSourceRate * (2 * unit(rng) - 1);
  }
  if (d.role[0] == DomainRole::kFixedPressure) d.role[0] = DomainRole::kFree;  // >= 1 unknown
  auto add = [&](int a, int b) {
    const double ap =
        kRandomBaseAperture * std::pow(10.0, shape.aperture_decades * (2 * unit(rng) - 1));
    testing::AddPipe(d, a, b, kRandomPipeLength, ap,
                     ap * ap * ap / (12.0 * kRandomViscosity * kRandomPipeLength));
  };
  // Two components when `split` > 0: domains [0, split) and [split, n) are never joined.
  const int split = (n >= 4 && unit(rng) < 0.25) ? n / 2 : 0;
  for (int i = 1; i < n; ++i) {
    const int lo = (split > 0 && i >= split) ? split : 0;
    if (i == lo) continue;
    add(lo + static_cast<int>(unit(rng) * (i - lo)), i);
  }
  const int chords = static_cast<int>(unit(rng) * n);
  for (int k = 0; k < chords; ++k) {
    const int a = static_cast<int>(unit(rng) * n);
    const int b = static_cast<int>(unit(rng) * n);
    if (a == b || (split > 0 && (a < split) != (b < split))) continue;
    add(a, b);
  }
  return testing::MakeOrDie(std::move(d));
}

}  // namespace seep::core::stability
