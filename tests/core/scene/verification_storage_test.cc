// The scene's storage model: the storage factor (docs/physics.md §1.2 reading (b)): V_s = f x V_p
// speeds the transient up by 1/f, so the diffusion series holds at T = c t / L^2 with
// c = k K_f / (mu f n_s); and the volume floor (§4.4 remedy 1).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "scene_test_util.h"
#include "seep/core/network/scene_network.h"

namespace seep::core {
namespace {

using scene_test::kAperture;
using scene_test::kRadius;
using scene_test::kViscosity;
using scene_test::Metric;

// The square 41 x 4 lattice of examples/transient_1d.textproto: p1 = 1e5 Pa held at the inlet
// from t = 0, the outlet at 0, explicit with pore storage (n_s = V_p/V_d = 1 - pi/4).
SceneSpec DiffusionScene(double storage_factor, double end_time_s) {
  SceneSpec s = scene_test::LatticeScene(LatticeKind::kSquare, 41, 4, FlowAxis::kX);
  s.fluid.bulk_modulus_pa = 2.2e9;
  s.solver.kind = SolverKind::kExplicit;
  s.solver.storage = StorageVolume::kPore;
  s.solver.dt_factor = 0.9;
  s.solver.end_time_s = end_time_s;
  s.solver.storage_factor = storage_factor;
  return s;
}

// q_out / q_steady = 1 + 2 sum (-1)^n exp(-n^2 pi^2 T) (docs/physics.md §3.2 (a)).
double OutflowRatioSeries(double T) {
  double sum = 1.0;
  for (int n = 1; n <= 50; ++n) {
    sum += 2.0 * (n % 2 == 0 ? 1.0 : -1.0) * std::exp(-n * n * M_PI * M_PI * T);
  }
  return sum;
}

double OutflowRatio(const SceneSpec& scene) {
  Result<RunReport> report = RunScene(scene, {});
  EXPECT_TRUE(report.ok()) << report.status().message();
  if (!report.ok()) return 0.0;
  // q_steady = k (H / L) p1 / mu: three rows of domains across H = 3 x 2R, L = 41 x 2R,
  // k = a0^3 / (24 R).
  const double k = kAperture * kAperture * kAperture / (24.0 * kRadius);
  const double steady = k * (3.0 * 2.0 * kRadius) / (41.0 * 2.0 * kRadius) * 1e5 / kViscosity;
  std::printf("storage factor %g: %g steps to t = %g s, q_out / q_steady = %.6f\n",
              scene.solver.storage_factor, Metric(*report, "steps"), scene.solver.end_time_s,
              Metric(*report, "outflow_m2_per_s") / steady);
  return Metric(*report, "outflow_m2_per_s") / steady;
}

TEST(Verification, StorageFactorScalesTheDiffusivity) {
  const double n_s = 1.0 - M_PI / 4.0;
  const double k = kAperture * kAperture * kAperture / (24.0 * kRadius);
  const double length = 41.0 * 2.0 * kRadius;
  const double factor = 0.37;  // unlike the examples (1)
  const double c = k * 2.2e9 / (kViscosity * factor * n_s);
  const double T = 0.2;
  const double t = T * length * length / c;
  const double expected = OutflowRatioSeries(T);
  ASSERT_NEAR(expected, 0.72292, 1e-5);
  // The network of 40 cells along x is 0.07 % above the series at f = 1 (spatial discretisation,
  // the same at any f: f only rescales time); 0.5 % fails a factor applied twice or not at all
  // (T would be 0.074 or 0.54: ratios 0.15 and 0.99).
  EXPECT_NEAR(OutflowRatio(DiffusionScene(factor, t)), expected, 0.005 * expected);
  // The same physical time without the factor is an earlier T: the factor did the speed-up.
  const double unscaled = OutflowRatio(DiffusionScene(1.0, t));
  EXPECT_NEAR(unscaled, OutflowRatioSeries(T * factor), 0.02);
}

TEST(Verification, StorageFactorOutsideItsRangeNamesTheField) {
  for (const double bad : {0.0, -0.5, 1.5, std::nan("")}) {
    const Status status = ValidateScene(DiffusionScene(bad, 1e-3));
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(status.message().rfind("scene.solver.storage_factor: must lie in (0, 1]", 0), 0u)
        << status.message();
  }
}

}  // namespace
}  // namespace seep::core

namespace seep::core {
namespace {

using scene_test::Metric;

// The volume floor (docs/physics.md §4.4 remedy 1) on a random packing, whose small pores set the
// explicit step: dt_crit = min_i max(V_p,i, a <V_p>) / (K_f sum_j C_ij), computed here from the
// network.
TEST(Verification, StorageFloorLiftsTheCriticalStepOfSmallPores) {
  SceneSpec scene = scene_test::RandomScene(7);
  scene.solver.kind = SolverKind::kExplicit;
  scene.solver.storage = StorageVolume::kPore;
  scene.solver.dt_factor = 0.9;
  scene.solver.end_time_s = 2e-6;
  scene.fluid.bulk_modulus_pa = 2.2e9;
  const double fraction = 0.5;

  Result<SceneNetwork> net = BuildSceneNetwork(scene);
  ASSERT_TRUE(net.ok()) << net.status().message();
  const FlowNetwork& flow = net->flow;
  const auto role = flow.role();
  const auto pore = flow.pore_volume();
  std::vector<double> sum_c(flow.num_domains(), 0.0);
  for (std::size_t p = 0; p < flow.num_pipes(); ++p) {
    sum_c[static_cast<std::size_t>(flow.pipe_domain_a()[p])] += flow.pipe_conductance()[p];
    sum_c[static_cast<std::size_t>(flow.pipe_domain_b()[p])] += flow.pipe_conductance()[p];
  }
  double mean = 0.0;
  std::size_t free = 0;
  for (std::size_t d = 0; d < flow.num_domains(); ++d) {
    if (role[d] == DomainRole::kFixedPressure) continue;
    mean += pore[d];
    ++free;
  }
  mean /= static_cast<double>(free);
  double bare = std::numeric_limits<double>::infinity();
  double floored = bare;
  for (std::size_t d = 0; d < flow.num_domains(); ++d) {
    if (role[d] == DomainRole::kFixedPressure || !(sum_c[d] > 0.0)) continue;
    const double k_sum = scene.fluid.bulk_modulus_pa * sum_c[d];
    bare = std::min(bare, pore[d] / k_sum);
    floored = std::min(floored, std::max(pore[d], fraction * mean) / k_sum);
  }
  ASSERT_GT(floored, 2.0 * bare)
      << "the floor must lift the limiting pore for the test to mean anything";

  Result<RunReport> without = RunScene(scene, {});
  ASSERT_TRUE(without.ok()) << without.status().message();
  EXPECT_DOUBLE_EQ(Metric(*without, "dt_crit_s"), bare);
  scene.solver.storage_floor_fraction = fraction;
  Result<RunReport> with = RunScene(scene, {});
  ASSERT_TRUE(with.ok()) << with.status().message();
  EXPECT_DOUBLE_EQ(Metric(*with, "dt_crit_s"), floored);
  // Every update and every balance uses the floored V_s: the books stay closed.
  EXPECT_LE(Metric(*with, "mass_balance_error_max"), 1e-10);
  std::printf("storage floor %g x <V_p> = %.4g m^2: dt_crit %.4g s -> %.4g s (%.1fx)\n", fraction,
              fraction * mean, bare, floored, floored / bare);
}

// A floor adds storage only: the steady state is the same to the bit.
TEST(Verification, StorageFloorLeavesTheSteadyStateAlone) {
  SceneSpec scene = scene_test::RandomScene(7);
  Result<RunReport> bare = RunScene(scene, {});
  scene.solver.storage_floor_fraction = 0.2;
  Result<RunReport> floored = RunScene(scene, {});
  ASSERT_TRUE(bare.ok() && floored.ok());
  EXPECT_EQ(Metric(*floored, "permeability_m2"), Metric(*bare, "permeability_m2"));
}

TEST(Verification, StorageFloorOutsideItsRangeNamesTheField) {
  for (const double bad : {1.0, -0.1, std::nan("")}) {
    SceneSpec scene = scene_test::RandomScene(7);
    scene.solver.storage_floor_fraction = bad;
    const Status status = ValidateScene(scene);
    EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(status.message().rfind("scene.solver.storage_floor_fraction: must lie in [0, 1)", 0),
              0u)
        << status.message();
  }
}

}  // namespace
}  // namespace seep::core
