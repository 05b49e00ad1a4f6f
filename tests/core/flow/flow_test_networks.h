// Networks built by index arithmetic for the flow tests: chains, square lattices, brick-wall
// honeycombs and seeded random networks. Nothing here knows about particles.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "seep/core/flow/flow_network.h"

namespace seep::core::testing {

// Equal disks of radius R, PFC pipe length L = 2R (docs/physics.md §0, §1.3).
struct LatticeParams {
  double radius = 1e-3;         // R, m
  double viscosity = 1e-3;      // mu, Pa s
  double bulk_modulus = 2e9;    // K_f, Pa
  double permeability = 1e-12;  // k target, m^2 (square: a = (24 R k)^(1/3))
  double Aperture() const { return std::cbrt(24.0 * radius * permeability); }
  // C = a^3/(12 mu L) with L = 2R, i.e. a^3/(24 mu R).
  double Conductance() const {
    const double a = Aperture();
    return a * a * a / (24.0 * viscosity * radius);
  }
  double SquareApparentVolume() const { return 4.0 * radius * radius; }
  double SquarePoreVolume() const { return (4.0 - std::numbers::pi) * radius * radius; }
  double HexApparentVolume() const { return std::numbers::sqrt3 * radius * radius; }
  double HexPoreVolume() const {
    return (std::numbers::sqrt3 - std::numbers::pi / 2) * radius * radius;
  }
};

inline void AddDomain(FlowNetworkData& d, double apparent, double pore, double pressure = 0.0,
                      DomainRole role = DomainRole::kFree) {
  d.apparent_volume.push_back(apparent);
  d.pore_volume.push_back(pore);
  d.pressure.push_back(pressure);
  d.role.push_back(role);
  d.source_rate.push_back(0.0);
}

inline void AddPipe(FlowNetworkData& d, std::int32_t a, std::int32_t b, double length,
                    double aperture, double conductance) {
  d.pipe_domain_a.push_back(a);
  d.pipe_domain_b.push_back(b);
  d.pipe_length.push_back(length);
  d.pipe_aperture.push_back(aperture);
  d.pipe_conductance.push_back(conductance);
}

inline FlowNetwork MakeOrDie(FlowNetworkData data) {
  auto net = FlowNetwork::Create(std::move(data));
  EXPECT_TRUE(net.ok()) << net.status().ToString();
  return std::move(net).value();
}

// Chain of domains 0..n_cells (n_cells + 1 nodes) with identical pipes; node 0 fixed at p_left;
// node n_cells fixed at 0 unless no_flow_end. Interior pressures start at 0.
inline FlowNetwork MakeChain(int n_cells, const LatticeParams& lp, double apparent, double pore,
                             bool no_flow_end, double p_left = 1.0) {
  FlowNetworkData d;
  for (int i = 0; i <= n_cells; ++i) {
    DomainRole role = DomainRole::kFree;
    double p = 0.0;
    if (i == 0) {
      role = DomainRole::kFixedPressure;
      p = p_left;
    } else if (i == n_cells && !no_flow_end) {
      role = DomainRole::kFixedPressure;
    }
    AddDomain(d, apparent, pore, p, role);
  }
  for (int i = 0; i < n_cells; ++i) {
    AddPipe(d, i, i + 1, 2.0 * lp.radius, lp.Aperture(), lp.Conductance());
  }
  return MakeOrDie(std::move(d));
}

// Square-lattice domains (the cells of an nx x ny disk packing): mx = nx-1 columns by my = ny-1
// rows, numbered row-major (id = j*mx + i); pipes between edge neighbours.
inline FlowNetworkData MakeSquareLatticeData(int mx, int my, const LatticeParams& lp) {
  FlowNetworkData d;
  for (int j = 0; j < my; ++j) {
    for (int i = 0; i < mx; ++i) AddDomain(d, lp.SquareApparentVolume(), lp.SquarePoreVolume());
  }
  for (int j = 0; j < my; ++j) {
    for (int i = 0; i < mx; ++i) {
      const int id = j * mx + i;
      if (i + 1 < mx) AddPipe(d, id, id + 1, 2.0 * lp.radius, lp.Aperture(), lp.Conductance());
      if (j + 1 < my) AddPipe(d, id, id + mx, 2.0 * lp.radius, lp.Aperture(), lp.Conductance());
    }
  }
  return d;
}

// Brick-wall honeycomb: every node links to its left/right neighbours and, when (i + j) is even,
// to the node above. Degree 3 inside, bipartite: the topology of the triangle domains of a
// hexagonal packing. Hex cell volumes, same pipe as the square lattice.
inline FlowNetworkData MakeHoneycombData(int mx, int my, const LatticeParams& lp) {
  FlowNetworkData d;
  for (int j = 0; j < my; ++j) {
    for (int i = 0; i < mx; ++i) AddDomain(d, lp.HexApparentVolume(), lp.HexPoreVolume());
  }
  for (int j = 0; j < my; ++j) {
    for (int i = 0; i < mx; ++i) {
      const int id = j * mx + i;
      if (i + 1 < mx) AddPipe(d, id, id + 1, 2.0 * lp.radius, lp.Aperture(), lp.Conductance());
      if (j + 1 < my && (i + j) % 2 == 0) {
        AddPipe(d, id, id + mx, 2.0 * lp.radius, lp.Aperture(), lp.Conductance());
      }
    }
  }
  return d;
}

// Seeded random closed network: a ring (connected) plus random chords, log-uniform volumes and
// conductances, uniform random pressures. No fixed nodes.
inline FlowNetworkData MakeRandomClosedData(int n, int extra_pipes, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto log_uniform = [&](double lo, double hi) { return lo * std::pow(hi / lo, unit(rng)); };
  FlowNetworkData d;
  for (int i = 0; i < n; ++i) {
    const double vp = log_uniform(1e-8, 1e-7);
    AddDomain(d, 2.0 * vp, vp, 1e6 * unit(rng));
  }
  auto add = [&](int a, int b) { AddPipe(d, a, b, 1e-3, 1e-5, log_uniform(1e-10, 1e-9)); };
  for (int i = 0; i < n; ++i) add(i, (i + 1) % n);
  for (int k = 0; k < extra_pipes; ++k) {
    const int a = static_cast<int>(unit(rng) * n);
    int b = static_cast<int>(unit(rng) * n);
    if (b == a) b = (a + 1 + n / 2) % n;
    add(a, b);
  }
  return d;
}

}  // namespace seep::core::testing
