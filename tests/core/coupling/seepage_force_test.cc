// V15 (seepage force, docs/physics.md §2.5, §5): a permeameter at steady state through the scene
// pipeline (BuildSceneNetwork + steady solver), forces by the chord rule with the reservoirs
// acting on the end faces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "seep/core/coupling/pressure_forces.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/network/scene_network.h"

namespace seep::core {
namespace {

constexpr double kRadius = 1e-3;
constexpr double kInlet = 2e5;
constexpr double kOutlet = 5e4;

SceneSpec Permeameter(PackingSource source, double contact_gap) {
  SceneSpec s;
  s.name = "v15";
  s.packing.source = std::move(source);
  s.packing.contact_gap_m = contact_gap;
  s.fluid.viscosity_pa_s = 1e-3;
  s.aperture.residual_aperture_m = 1e-5;
  s.aperture.reference_force_n = 1e3;
  s.aperture.gap_multiplier = 0.5;
  s.boundary.axis = FlowAxis::kX;
  s.boundary.inlet_pressure_pa = kInlet;
  s.boundary.outlet_pressure_pa = kOutlet;
  s.solver.kind = SolverKind::kSteady;
  return s;
}

struct Solved {
  SceneNetwork net;
  std::vector<double> fx, fy;
  std::vector<double> arcs;      // outside pressure of every outer-loop arc
  double low = 0.0, high = 0.0;  // the sample's ends along x (particle surfaces)
  double layer = 0.0;            // edge-layer depth of the scene builder
};

// The reservoir of a hull contact, by the scene builder's rule (scene_network.h): both particles
// in the edge layer of one end.
Solved SolveAndApplyForces(const SceneSpec& scene) {
  Solved s;
  auto built = BuildSceneNetwork(scene);
  EXPECT_TRUE(built.ok()) << built.status().ToString();
  s.net = std::move(*built);
  auto report = SolveSteadyState(s.net.flow);
  EXPECT_TRUE(report.ok()) << report.status().ToString();

  const Packing& p = s.net.packing;
  const DomainNetwork& d = s.net.domains;
  s.low = std::numeric_limits<double>::infinity();
  s.high = -s.low;
  for (std::size_t i = 0; i < p.size(); ++i) {
    s.low = std::min(s.low, p.x[i] - p.radius[i]);
    s.high = std::max(s.high, p.x[i] + p.radius[i]);
  }
  s.layer = s.net.mean_radius_m * (1.0 + 1e-9);
  std::vector<double> reservoir(d.num_boundary_pipes(), std::nan(""));
  for (std::size_t k = 0; k < d.num_boundary_pipes(); ++k) {
    const auto c = static_cast<std::size_t>(d.boundary_pipe_contact[k]);
    const auto i = static_cast<std::size_t>(s.net.contacts.i[c]);
    const auto j = static_cast<std::size_t>(s.net.contacts.j[c]);
    const bool inlet =
        p.x[i] - p.radius[i] <= s.low + s.layer && p.x[j] - p.radius[j] <= s.low + s.layer;
    const bool outlet =
        p.x[i] + p.radius[i] >= s.high - s.layer && p.x[j] + p.radius[j] >= s.high - s.layer;
    if (inlet != outlet) reservoir[k] = inlet ? kInlet : kOutlet;
  }
  const std::span<const double> domain_pressure = s.net.flow.pressure().first(d.num_domains());
  OuterArcPressures outer;
  EXPECT_TRUE(outer.Compute(d, domain_pressure, reservoir, &s.arcs).ok());
  s.fx.assign(p.size(), 0.0);
  s.fy.assign(p.size(), 0.0);
  const Status st = AddPressureForces(ViewOf(p), d, domain_pressure, s.arcs, s.fx, s.fy);
  EXPECT_TRUE(st.ok()) << st.ToString();
  return s;
}

double Sum(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s;
}

// Exposed height of an end face on a lattice: the chords of the end column's arcs run from the
// contact of its top particle with its row neighbour to that of its bottom particle, both at
// their centres' height, so H_exposed = y(top end particle) - y(bottom end particle).
double EndFaceHeight(const Solved& s, bool inlet) {
  const Packing& p = s.net.packing;
  double top = -std::numeric_limits<double>::infinity();
  double bottom = -top;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const bool in_layer =
        inlet ? p.x[i] - p.radius[i] <= s.low + s.layer : p.x[i] + p.radius[i] >= s.high - s.layer;
    if (!in_layer) continue;
    top = std::max(top, p.y[i]);
    bottom = std::min(bottom, p.y[i]);
  }
  return top - bottom;
}

// Total fluid force on the skeleton along the flow = p_in H_in - p_out H_out. Each domain's
// chords close, so the interior pressures cancel exactly and only round-off of the sum over
// ~4 N chord terms of size p R remains: ~1e-15 p R sqrt(N) relative to (p_in - p_out) H. The
// 1e-10 of docs/physics.md §5 is ample.
void ExpectTotalSeepageForce(const SceneSpec& scene, double expected_height, const char* name) {
  SCOPED_TRACE(name);
  const Solved s = SolveAndApplyForces(scene);
  const double h_in = EndFaceHeight(s, true);
  const double h_out = EndFaceHeight(s, false);
  EXPECT_NEAR(h_in, expected_height, 1e-12 * expected_height);
  EXPECT_NEAR(h_out, expected_height, 1e-12 * expected_height);
  const double expected = (kInlet - kOutlet) * expected_height;
  EXPECT_NEAR(Sum(s.fx), expected, 1e-10 * expected);
  // Top and bottom see the same pocket pressures (the rows beside them): no net lift.
  EXPECT_NEAR(Sum(s.fy), 0.0, 1e-10 * expected);
}

TEST(SeepageForce, V15_SquareLatticeColumn) {
  constexpr std::uint32_t kColumns = 16, kRows = 6;
  ExpectTotalSeepageForce(
      Permeameter(LatticePackingSpec{LatticeKind::kSquare, kColumns, kRows, kRadius}, 0.0),
      2.0 * kRadius * (kRows - 1), "square 16x6");
}

TEST(SeepageForce, V15_HexLatticeColumn) {
  constexpr std::uint32_t kColumns = 14, kRows = 7;
  ExpectTotalSeepageForce(
      Permeameter(LatticePackingSpec{LatticeKind::kHex, kColumns, kRows, kRadius}, 0.0),
      std::sqrt(3.0) * kRadius * (kRows - 1), "hex 14x7");
}

// The distributed seepage force: the steady field of a square lattice is linear in x (V5), so a
// particle inside the sample, between four domains, feels -dp/dx times its cell area 4R^2 along
// x and nothing along y. The steady solve is exact to the direct solver's round-off (~1e-12
// relative on the pressures); the force is a difference of pressures of adjacent domains
// (~dp of 1/16 of the drop), hence 1e-9 relative.
TEST(SeepageForce, V15_SquareLatticeBodyForceIsMinusGradientTimesCellArea) {
  constexpr std::uint32_t kColumns = 16, kRows = 6;
  const Solved s = SolveAndApplyForces(
      Permeameter(LatticePackingSpec{LatticeKind::kSquare, kColumns, kRows, kRadius}, 0.0));
  const DomainNetwork& d = s.net.domains;
  // dp/dx from the pressures of two domains of one row, a column apart (2R).
  const auto domain_at = [&](double x, double y) {
    for (std::size_t k = 0; k < d.num_domains(); ++k) {
      if (std::abs(d.centroid_x[k] - x) < 1e-3 * kRadius &&
          std::abs(d.centroid_y[k] - y) < 1e-3 * kRadius) {
        return k;
      }
    }
    ADD_FAILURE() << "no domain at " << x << ", " << y;
    return std::size_t{0};
  };
  const double p_a = s.net.flow.pressure()[domain_at(4 * kRadius, 4 * kRadius)];
  const double p_b = s.net.flow.pressure()[domain_at(6 * kRadius, 4 * kRadius)];
  const double gradient = (p_b - p_a) / (2 * kRadius);
  ASSERT_LT(gradient, 0.0);
  const double expected = -gradient * 4.0 * kRadius * kRadius;
  std::uint32_t checked = 0;
  for (std::uint32_t j = 1; j + 1 < kRows; ++j) {
    for (std::uint32_t i = 1; i + 1 < kColumns; ++i) {
      const std::size_t id = j * kColumns + i;
      EXPECT_NEAR(s.fx[id], expected, 1e-9 * expected) << "particle " << i << ", " << j;
      EXPECT_NEAR(s.fy[id], 0.0, 1e-9 * expected) << "particle " << i << ", " << j;
      ++checked;
    }
  }
  EXPECT_EQ(checked, (kColumns - 2) * (kRows - 2));
}

// On a random packing the ends are irregular and the no-flow sides' chords are tilted, so the
// total force is the boundary integral sum over outer arcs of p_arc * t_y (t = chord), which is
// computed here directly from the outer walk's contact points. The interior pressures must
// cancel exactly, whatever the solved field: 1e-10 as above.
TEST(SeepageForce, V15_RandomPackingColumnEqualsBoundaryIntegral) {
  RandomPackingSpec r;
  r.seed = 5;
  r.width_m = 0.04;
  r.height_m = 0.02;
  r.min_radius_m = 0.8e-3;
  r.max_radius_m = 1.0e-3;
  r.particle_count = 300;
  r.target_porosity = 0.2;
  const Solved s = SolveAndApplyForces(Permeameter(r, 2e-5));
  const DomainNetwork& d = s.net.domains;
  const Packing& p = s.net.packing;
  EXPECT_GT(s.net.inlet_pipes, 3);
  EXPECT_GT(s.net.outlet_pipes, 3);
  ASSERT_FALSE(s.arcs.empty());
  double boundary = 0.0;
  for (std::size_t f = 0; f < d.num_outer_faces(); ++f) {
    const auto b = static_cast<std::size_t>(d.outer_offsets[f]);
    const auto e = static_cast<std::size_t>(d.outer_offsets[f + 1]);
    // y of the contact point between outer entry q and the next entry.
    auto contact_y = [&](std::size_t q) {
      const auto a = static_cast<std::size_t>(d.outer_particles[q]);
      const auto n = static_cast<std::size_t>(d.outer_particles[q + 1 < e ? q + 1 : b]);
      const double dist = std::hypot(p.x[n] - p.x[a], p.y[n] - p.y[a]);
      const double gap = dist - p.radius[a] - p.radius[n];
      const double along =
          gap >= 0.0 ? p.radius[a] + 0.5 * gap
                     : (dist * dist + p.radius[a] * p.radius[a] - p.radius[n] * p.radius[n]) /
                           (2.0 * dist);
      return p.y[a] + along / dist * (p.y[n] - p.y[a]);
    };
    for (std::size_t q = b; q < e; ++q) {
      boundary += s.arcs[q] * (contact_y(q) - contact_y(q > b ? q - 1 : e - 1));
    }
  }
  const double scale = (kInlet - kOutlet) * r.height_m;
  EXPECT_NEAR(Sum(s.fx), boundary, 1e-10 * scale);
  // The ends dominate: within the side-pocket tilt of (p_in - p_out) times the height.
  EXPECT_GT(Sum(s.fx), 0.5 * scale);
  EXPECT_LT(Sum(s.fx), 1.5 * scale);
}

}  // namespace
}  // namespace seep::core
