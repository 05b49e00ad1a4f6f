// V12 (docs/physics.md §3.3, §5): steady radial flow from a central borehole held at p_w to an
// outer reservoir at p_e, against the Thiem solution
//   p(r) = p_w + (p_e - p_w) ln(r / r_w) / ln(r_e / r_w),  Q = 2 pi k (p_w - p_e) / (mu
//   ln(r_e/r_w)).
// The effective well radius r_w,eff of the discrete hole is fitted from the profile
// (docs/physics.md §3.3, DEM caveats); r_e is the outer reservoir's effective radius from the
// network; k is the exact lattice value (hex) or the permeameter value of the same packing
// (random).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <variant>
#include <vector>

#include "scene_test_util.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/reference/radial_profile.h"
#include "seep/core/run/run_scene.h"

namespace seep::core {
namespace {

using scene_test::kAperture;
using scene_test::kRadius;
using scene_test::kViscosity;
using scene_test::Metric;

constexpr double kWellPressure = 1e5;
constexpr double kOuterPressure = 0.0;

struct ThiemResult {
  double r_w_eff = 0.0;
  double r_e = 0.0;
  double profile_error = 0.0;  // max |p - p_Thiem| / (p_w - p_e) over the window's domains
  double ring_error = 0.0;     // the same for ring means (rings 2 R wide)
  double q_error = 0.0;        // |Q - Q_Thiem| / Q_Thiem
  int window_domains = 0;
};

// Runs a radial scene and compares it with Thiem for permeability k.
ThiemResult CompareWithThiem(const SceneSpec& scene, double k) {
  ThiemResult out;
  auto report = RunScene(scene, {});
  EXPECT_TRUE(report.ok()) << report.status().ToString();
  auto net = BuildSceneNetwork(scene);
  EXPECT_TRUE(net.ok()) << net.status().ToString();
  if (!report.ok() || !net.ok()) return out;
  auto solved = SolveSteadyState(net->flow);
  EXPECT_TRUE(solved.ok()) << solved.status().ToString();

  const double q = Metric(*report, "well_flow_rate_m2_per_s");
  EXPECT_NEAR(Metric(*report, "outer_flow_rate_m2_per_s") / q, 1.0, 1e-9);  // steady balance
  out.r_e = Metric(*report, "outer_reservoir_radius_m");
  EXPECT_NEAR(out.r_e, net->outer_reservoir_radius_m, 1e-15);

  // Window 3 R < r < 0.8 r_e, outside the well domain; least squares p = A + B ln r.
  const double r_min = 3.0 * net->mean_radius_m + scene.boundary.radial->well_radius_m;
  const double r_max = 0.8 * out.r_e;
  auto fit = FitRadialProfile(*net, r_min, r_max);
  EXPECT_TRUE(fit.ok()) << fit.status().ToString();
  if (!fit.ok()) return out;
  out.window_domains = static_cast<int>(fit->ln_r.size());
  out.r_w_eff = fit->EffectiveWellRadius(kWellPressure);

  const double dp = kWellPressure - kOuterPressure;
  const double log_ratio = std::log(out.r_e / out.r_w_eff);
  auto thiem = [&](double log_r) {
    return kWellPressure - dp * (log_r - std::log(out.r_w_eff)) / log_ratio;
  };
  for (std::size_t i = 0; i < fit->ln_r.size(); ++i) {
    out.profile_error =
        std::max(out.profile_error, std::abs(fit->pressure[i] - thiem(fit->ln_r[i])) / dp);
  }
  for (const RingMean& ring : RingMeans(*fit, r_min, r_max, 2.0 * net->mean_radius_m)) {
    out.ring_error = std::max(out.ring_error, std::abs(ring.pressure - thiem(ring.ln_r)) / dp);
  }
  const double q_thiem = 2.0 * std::numbers::pi * k * dp / (kViscosity * log_ratio);
  out.q_error = std::abs(q - q_thiem) / q_thiem;
  return out;
}

SceneSpec RadialHexScene() {
  SceneSpec s = scene_test::LatticeScene(LatticeKind::kHex, 70, 80, FlowAxis::kX);
  s.boundary.radial =
      RadialBoundarySpec{5.0 * kRadius, 64.0 * kRadius, kWellPressure, kOuterPressure};
  return s;
}

TEST(Verification, V12_Thiem) {
  const double k = kAperture * kAperture * kAperture / (24.0 * std::sqrt(3.0) * kRadius);
  const ThiemResult r = CompareWithThiem(RadialHexScene(), k);
  // Measured: ring means 0.04%, single domains 2.3%, Q 0.03% (r_w,eff = 5.43 R for a 5 R hole).
  EXPECT_GT(r.window_domains, 1000);
  EXPECT_LT(r.ring_error, 0.03) << "r_w,eff = " << r.r_w_eff << " m";
  EXPECT_LT(r.profile_error, 0.05);
  EXPECT_LT(r.q_error, 0.03);
}

// A square seeded random packing, 0.1 m wide (about 3000 particles), generated once and passed on
// as an explicit particle list.
SceneSpec RandomSquareScene() {
  SceneSpec s = scene_test::RandomScene(11);
  auto& random = std::get<RandomPackingSpec>(s.packing.source);
  random.width_m = 0.1;
  random.height_m = 0.1;
  random.particle_count = 3000;
  auto packing = BuildScenePacking(s.packing);
  EXPECT_TRUE(packing.ok()) << packing.status().ToString();
  if (packing.ok()) s.packing.source = ParticleListSpec{packing->x, packing->y, packing->radius};
  return s;
}

double PermeameterK(SceneSpec scene, FlowAxis axis) {
  scene.boundary.axis = axis;
  auto report = RunScene(scene, {});
  EXPECT_TRUE(report.ok()) << report.status().ToString();
  return report.ok() ? Metric(*report, "permeability_m2") : 0.0;
}

TEST(Verification, V12_ThiemRandomPacking) {
  const SceneSpec box = RandomSquareScene();
  // 2D radial flow in an anisotropic medium sees sqrt(kx ky).
  const double kx = PermeameterK(box, FlowAxis::kX);
  const double ky = PermeameterK(box, FlowAxis::kY);
  SceneSpec radial = box;
  radial.boundary.radial = RadialBoundarySpec{0.006, 0.048, kWellPressure, kOuterPressure};
  const ThiemResult r = CompareWithThiem(radial, std::sqrt(kx * ky));
  // Measured: ring means 2.5%, Q 4.5%. Single domains scatter by up to 11% of dp about the
  // profile (local disorder), so the profile is compared ring by ring.
  EXPECT_GT(r.window_domains, 500);
  EXPECT_LT(r.ring_error, 0.05) << "r_w,eff = " << r.r_w_eff << " m";
  EXPECT_LT(r.q_error, 0.10);
}

// Rate out of the well domain into the network, m^2/s.
double WellRate(const SceneNetwork& net) {
  const FlowNetwork& f = net.flow;
  const auto p = f.pressure();
  double q = 0.0;
  for (std::size_t k = 0; k < f.num_pipes(); ++k) {
    const std::int32_t a = f.pipe_domain_a()[k];
    const std::int32_t b = f.pipe_domain_b()[k];
    const double flow_b_to_a =
        f.pipe_conductance()[k] * (p[static_cast<std::size_t>(b)] - p[static_cast<std::size_t>(a)]);
    if (b == net.well_domain) q += flow_b_to_a;
    if (a == net.well_domain) q -= flow_b_to_a;
  }
  return q;
}

// V13 (docs/physics.md §3.3, §5): a pressure step dp at the well of an initially uniform medium.
// The dimensionless rate q_D = Q mu / (2 pi k dp) against the Stehfest table of K1(sqrt s)/(sqrt s
// K0(sqrt s)) at t_D = c t / r_w^2, c = k K_f / (mu n_s), with the effective well radius fitted
// from the steady Thiem profile of the same network (docs/physics.md §3.3), and the outer reservoir
// far enough that the front has not reached it ((r_e - r_w)^2 >> 4 c t).
TEST(Verification, V13_RadialTransientConstantPressure) {
  const double k = kAperture * kAperture * kAperture / (24.0 * std::sqrt(3.0) * kRadius);
  SceneSpec scene = scene_test::LatticeScene(LatticeKind::kHex, 150, 175, FlowAxis::kX);
  scene.boundary.radial =
      RadialBoundarySpec{3.0 * kRadius, 145.0 * kRadius, kWellPressure, kOuterPressure};
  const ThiemResult steady = CompareWithThiem(scene, k);
  ASSERT_GT(steady.r_w_eff, 0.0);

  auto net = BuildSceneNetwork(scene);
  ASSERT_TRUE(net.ok()) << net.status().ToString();
  // Storage V_s = V_p: n_s is the pore fraction of the free domains.
  double pore = 0.0;
  double apparent = 0.0;
  for (std::size_t d = 0; d < net->domains.num_domains(); ++d) {
    if (static_cast<std::int32_t>(d) == net->well_domain) continue;
    pore += net->domains.pore_volume[d];
    apparent += net->domains.apparent_volume[d];
  }
  const double bulk_modulus = 2.2e9;
  const double diffusivity = k * bulk_modulus / (kViscosity * (pore / apparent));
  const double t_unit = steady.r_w_eff * steady.r_w_eff / diffusivity;  // t for t_D = 1

  ImplicitSolverOptions options;
  options.bulk_modulus = bulk_modulus;
  options.storage.volume = StorageVolume::kPore;
  options.diagnostics = false;
  auto solver = ImplicitSolver::Create(options);
  ASSERT_TRUE(solver.ok()) << solver.status().ToString();
  // Measured: q_D within 0.02% (t_D = 10) and 0.04% (t_D = 100) of the table, r_w,eff = 3.07 R for
  // a 3 R hole. Backward Euler at dt_D = 0.05 up to t_D = 10, then 0.5 up to 100 (O(dt/t) below
  // 0.5%).
  struct Checkpoint {
    double t_d;
    double step_d;
    double q_d;  // docs/physics.md §3.3 table
  };
  const Checkpoint checkpoints[] = {{10.0, 0.05, 0.53392}, {100.0, 0.5, 0.34556}};
  double t_d = 0.0;
  for (const Checkpoint& c : checkpoints) {
    const auto steps = static_cast<int>(std::lround((c.t_d - t_d) / c.step_d));
    for (int s = 0; s < steps; ++s) {
      auto step = solver->Step(net->flow, c.step_d * t_unit);
      ASSERT_TRUE(step.ok()) << step.status().ToString();
    }
    t_d = c.t_d;
    const double q_d = WellRate(*net) * kViscosity /
                       (2.0 * std::numbers::pi * k * (kWellPressure - kOuterPressure));
    // The front has not reached the outer reservoir: (r_e - r_w)^2 / (4 c t) > 4, so its effect
    // on the well rate is of order exp(-4) of the transient part or less.
    EXPECT_GT(
        std::pow(steady.r_e - steady.r_w_eff, 2) / (4.0 * t_d * steady.r_w_eff * steady.r_w_eff),
        4.0);
    EXPECT_NEAR(q_d / c.q_d, 1.0, 0.05) << "t_D = " << t_d << ": q_D = " << q_d;
  }
}

}  // namespace
}  // namespace seep::core
