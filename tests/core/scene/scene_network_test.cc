// BuildSceneNetwork and ValidateScene for the radial boundary: errors name the field.
#include "seep/core/network/scene_network.h"

#include <gtest/gtest.h>

#include <string>

#include "scene_test_util.h"
#include "seep/core/run/run_scene.h"

namespace seep::core {
namespace {

SceneSpec Radial(double well_radius, double outer_radius) {
  SceneSpec s = scene_test::LatticeScene(LatticeKind::kHex, 30, 34, FlowAxis::kX);
  s.boundary.radial = RadialBoundarySpec{well_radius, outer_radius, 1e5, 0.0};
  return s;
}

void ExpectError(const Status& status, StatusCode code, const std::string& field) {
  SCOPED_TRACE(field);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), code);
  EXPECT_EQ(status.message().rfind(field, 0), 0u) << status.message();
}

TEST(SceneNetwork, RadialBoundaryHasOneWellAndAnOuterReservoir) {
  auto net = BuildSceneNetwork(Radial(4e-3, 25e-3));
  ASSERT_TRUE(net.ok()) << net.status().ToString();
  ASSERT_GE(net->well_domain, 0);
  const auto well = static_cast<std::size_t>(net->well_domain);
  EXPECT_EQ(net->flow.role()[well], DomainRole::kFixedPressure);
  EXPECT_EQ(net->flow.pressure()[well], 1e5);
  EXPECT_EQ(net->outer_node, static_cast<std::int32_t>(net->domains.num_domains()));
  EXPECT_EQ(net->flow.num_domains(), net->domains.num_domains() + 1);
  EXPECT_GT(net->outer_pipes, 0);
  // The well is the hole: far bigger than a lattice triangle (sqrt3 R^2).
  EXPECT_GT(net->domains.apparent_volume[well], 20.0 * std::sqrt(3.0) * 1e-6);
  // Every kept particle lies in the annulus; the outer reservoir sits near its edge.
  for (std::size_t i = 0; i < net->packing.size(); ++i) {
    const double r =
        std::hypot(net->packing.x[i] - net->well_x_m, net->packing.y[i] - net->well_y_m);
    EXPECT_GE(r, 4e-3);
    EXPECT_LE(r, 25e-3);
  }
  EXPECT_NEAR(net->outer_reservoir_radius_m, 25e-3, 3e-3);
}

TEST(SceneNetwork, RadialRunReportsTheWellRate) {
  auto report = RunScene(Radial(4e-3, 25e-3), {});
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  const double q = scene_test::Metric(*report, "well_flow_rate_m2_per_s");
  EXPECT_GT(q, 0.0);  // p_w > p_e: the well injects
  EXPECT_NEAR(scene_test::Metric(*report, "outer_flow_rate_m2_per_s") / q, 1.0, 1e-9);
}

// After a pressure step at the well the rate exceeds the steady rate and falls towards it.
TEST(SceneNetwork, RadialTransientRateFallsTowardsTheSteadyRate) {
  SceneSpec steady = Radial(4e-3, 25e-3);
  auto steady_report = RunScene(steady, {});
  ASSERT_TRUE(steady_report.ok()) << steady_report.status().ToString();
  const double q_steady = scene_test::Metric(*steady_report, "well_flow_rate_m2_per_s");
  double previous = 0.0;
  for (double end_time : {1e-4, 1e-3, 1e-2}) {
    SceneSpec transient = steady;
    transient.solver.kind = SolverKind::kImplicit;
    transient.solver.storage = StorageVolume::kPore;
    transient.solver.dt_factor = 1e4;
    transient.solver.end_time_s = end_time;
    auto report = RunScene(transient, {});
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    const double q = scene_test::Metric(*report, "well_flow_rate_m2_per_s");
    EXPECT_GT(q, q_steady) << "t = " << end_time;
    if (previous > 0.0) {
      EXPECT_LT(q, previous) << "t = " << end_time;
    }
    previous = q;
  }
}

TEST(SceneNetwork, RadialErrorsNameTheField) {
  ExpectError(ValidateScene(Radial(0.0, 25e-3)), StatusCode::kInvalidArgument,
              "scene.boundary.radial.well_radius_m:");
  ExpectError(ValidateScene(Radial(5e-3, 5e-3)), StatusCode::kInvalidArgument,
              "scene.boundary.radial.outer_radius_m:");
  SceneSpec nan_pressure = Radial(4e-3, 25e-3);
  nan_pressure.boundary.radial->outer_pressure_pa = std::nan("");
  ExpectError(ValidateScene(nan_pressure), StatusCode::kInvalidArgument,
              "scene.boundary.radial.outer_pressure_pa:");
  // A hole smaller than the distance to the nearest particle centre removes nothing.
  ExpectError(BuildSceneNetwork(Radial(1e-7, 25e-3)).status(), StatusCode::kInvalidArgument,
              "scene.boundary.radial.well_radius_m:");
  // A hole wider than the sample leaves no particle.
  ExpectError(BuildSceneNetwork(Radial(1.0, 2.0)).status(), StatusCode::kInvalidArgument,
              "scene.boundary.radial:");
}

}  // namespace
}  // namespace seep::core
