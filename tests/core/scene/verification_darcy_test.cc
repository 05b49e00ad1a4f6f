// V4 (lattice permeability) and V5 (Darcy linearity), docs/physics.md §5, through the scene
// pipeline: BuildSceneNetwork / RunScene with their reservoirs and Darcy length and width.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

#include "scene_test_util.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/run/run_scene.h"

namespace seep::core {
namespace {

using scene_test::kAperture;
using scene_test::kRadius;
using scene_test::LatticeScene;
using scene_test::Metric;
using scene_test::RandomScene;

// docs/physics.md §1.3 with L = 2R.
double SquareK() { return kAperture * kAperture * kAperture / (24.0 * kRadius); }
double HexK() { return kAperture * kAperture * kAperture / (24.0 * std::sqrt(3.0) * kRadius); }

double MeasuredK(const SceneSpec& scene) {
  auto report = RunScene(scene, {});
  EXPECT_TRUE(report.ok()) << report.status().ToString();
  if (!report.ok()) return 0.0;
  return Metric(*report, "permeability_m2");
}

struct LatticeCase {
  LatticeKind kind;
  FlowAxis axis;
  std::uint32_t columns;
  std::uint32_t rows;
};

TEST(Verification, V04_LatticePermeability) {
  const LatticeCase cases[] = {
      {LatticeKind::kSquare, FlowAxis::kX, 12, 7}, {LatticeKind::kSquare, FlowAxis::kX, 30, 20},
      {LatticeKind::kSquare, FlowAxis::kY, 9, 16}, {LatticeKind::kSquare, FlowAxis::kY, 3, 2},
      {LatticeKind::kHex, FlowAxis::kX, 12, 7},    {LatticeKind::kHex, FlowAxis::kX, 30, 20},
      {LatticeKind::kHex, FlowAxis::kX, 2, 2},     {LatticeKind::kHex, FlowAxis::kX, 5, 11},
  };
  for (const LatticeCase& c : cases) {
    SCOPED_TRACE(testing::Message()
                 << (c.kind == LatticeKind::kSquare ? "square " : "hex ") << c.columns << "x"
                 << c.rows << (c.axis == FlowAxis::kX ? " along x" : " along y"));
    const double expected = c.kind == LatticeKind::kSquare ? SquareK() : HexK();
    const double k = MeasuredK(LatticeScene(c.kind, c.columns, c.rows, c.axis));
    EXPECT_NEAR(k / expected, 1.0, 1e-8) << "k = " << k << ", expected " << expected;
  }
}

// Along y a hex lattice has zig-zag no-flow sides: the hull pipes there cut bonds that the linear
// pressure field of the infinite lattice loads, so the field is not exact near the sides and k
// carries a side-wall error of order R/H. It must shrink like 1/width towards a^3/(24 sqrt3 R).
TEST(Verification, V04_HexLatticeAlongYConvergesWithWidth) {
  double previous_error = 1.0;
  for (std::uint32_t columns : {6u, 12u, 24u, 48u}) {
    const double k = MeasuredK(LatticeScene(LatticeKind::kHex, columns, 12, FlowAxis::kY));
    const double error = std::abs(k / HexK() - 1.0);
    const double width_in_radii = 2.0 * (columns - 1);
    SCOPED_TRACE(testing::Message() << columns << " columns, relative error " << error);
    EXPECT_LT(error * width_in_radii, 0.6);  // about (R/sqrt3) / H of lost width
    EXPECT_LT(error, previous_error * 0.6);  // halves with each doubling of the width
    previous_error = error;
  }
}

// P along the axis: least-squares line through (centroid, pressure) of the domains, each weighted
// by its area V_d (the fit of the area-averaged field; tiny domains carry little fluid).
struct LineFit {
  double slope = 0.0;
  double r2 = 0.0;
};

LineFit FitPressure(const SceneNetwork& net, FlowAxis axis) {
  const auto pressure = net.flow.pressure();
  const std::size_t n = net.domains.num_domains();
  const auto& area = net.domains.apparent_volume;
  double sw = 0.0;
  double sx = 0.0;
  double sp = 0.0;
  for (std::size_t d = 0; d < n; ++d) {
    sw += area[d];
    sx += area[d] * (axis == FlowAxis::kX ? net.domains.centroid_x[d] : net.domains.centroid_y[d]);
    sp += area[d] * pressure[d];
  }
  const double mx = sx / sw;
  const double mp = sp / sw;
  double sxx = 0.0;
  double sxp = 0.0;
  double spp = 0.0;
  for (std::size_t d = 0; d < n; ++d) {
    const double x =
        (axis == FlowAxis::kX ? net.domains.centroid_x[d] : net.domains.centroid_y[d]) - mx;
    const double p = pressure[d] - mp;
    sxx += area[d] * x * x;
    sxp += area[d] * x * p;
    spp += area[d] * p * p;
  }
  LineFit fit;
  fit.slope = sxp / sxx;
  fit.r2 = sxp * sxp / (sxx * spp);
  return fit;
}

struct PermeameterRun {
  double q_over_dp = 0.0;
  LineFit fit;
};

PermeameterRun Permeameter(SceneSpec scene, double dp) {
  scene.boundary.inlet_pressure_pa = 2e5 + dp;
  scene.boundary.outlet_pressure_pa = 2e5;
  PermeameterRun run;
  auto report = RunScene(scene, {});
  EXPECT_TRUE(report.ok()) << report.status().ToString();
  if (!report.ok()) return run;
  const double q = 0.5 * (Metric(*report, "inflow_m2_per_s") + Metric(*report, "outflow_m2_per_s"));
  run.q_over_dp = q / dp;
  auto net = BuildSceneNetwork(scene);
  EXPECT_TRUE(net.ok()) << net.status().ToString();
  if (!net.ok()) return run;
  auto solved = SolveSteadyState(net->flow);
  EXPECT_TRUE(solved.ok()) << solved.status().ToString();
  run.fit = FitPressure(*net, scene.boundary.axis);
  return run;
}

void ExpectDarcyLinearity(const SceneSpec& scene, double q_tolerance, double min_r2) {
  const PermeameterRun base = Permeameter(scene, 1e5);
  ASSERT_GT(base.q_over_dp, 0.0);
  EXPECT_GT(base.fit.r2, min_r2);
  EXPECT_LT(base.fit.slope, 0.0);  // pressure falls from inlet to outlet
  for (double factor : {0.5, 2.0, 7.0}) {
    const PermeameterRun run = Permeameter(scene, factor * 1e5);
    SCOPED_TRACE(testing::Message() << "dp x " << factor);
    EXPECT_NEAR(run.q_over_dp / base.q_over_dp, 1.0, q_tolerance);
    EXPECT_GT(run.fit.r2, min_r2);
    EXPECT_NEAR(run.fit.slope / (factor * base.fit.slope), 1.0, q_tolerance);
  }
}

TEST(Verification, V05_DarcyLinearity) {
  {
    SCOPED_TRACE("square lattice");
    ExpectDarcyLinearity(LatticeScene(LatticeKind::kSquare, 20, 10, FlowAxis::kX), 1e-10, 0.999);
  }
  {
    SCOPED_TRACE("hex lattice");
    ExpectDarcyLinearity(LatticeScene(LatticeKind::kHex, 20, 10, FlowAxis::kX), 1e-10, 0.999);
  }
  {
    SCOPED_TRACE("random packing, seed 7");
    ExpectDarcyLinearity(RandomScene(7), 1e-10, 0.98);
  }
}

// On the lattices the interior pressure is exactly linear in x (R^2 = 1 to round-off).
TEST(Verification, V05_LatticePressureIsExactlyLinear) {
  for (LatticeKind kind : {LatticeKind::kSquare, LatticeKind::kHex}) {
    const PermeameterRun run = Permeameter(LatticeScene(kind, 16, 9, FlowAxis::kX), 1e5);
    EXPECT_NEAR(run.fit.r2, 1.0, 1e-12);
  }
}

}  // namespace
}  // namespace seep::core
