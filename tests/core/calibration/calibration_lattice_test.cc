// V4 (docs/physics.md §5) through the calibration: on a lattice with no contact force every
// aperture is a0, the affine estimate is the exact permeability (a linear pressure field solves the
// network, scene_network.h), so the first guess is already the answer, a0 = (24 R k)^(1/3)
// (square) or (24 sqrt3 R k)^(1/3) (hex), reached with one permeameter solve.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "calibration_test_scenes.h"
#include "seep/core/calibration/calibration.h"

namespace seep::core {
namespace {

using calibration_test::PermeameterSpec;

constexpr double kRadius = 1e-3;
constexpr double kLatticeTarget = 1e-13;
// The network solve is direct (CHOLMOD): k carries round-off of order 1e-13 relative, a0 a third
// of it; 1e-10 leaves three orders of margin.
constexpr double kLatticeTolerance = 1e-10;

TEST(CalibrationLattice, V4_SquareLatticeGivesExactApertureInOneSolve) {
  const std::uint32_t columns = 30;
  const std::uint32_t rows = 20;
  CalibrationSpec spec =
      PermeameterSpec(LatticePackingSpec{LatticeKind::kSquare, columns, rows, kRadius});
  spec.target_permeabilities_m2 = {kLatticeTarget};
  const auto records = CalibrateResidualAperture(spec);
  ASSERT_TRUE(records.ok()) << records.status().ToString();
  ASSERT_EQ(records->size(), 1u);
  const CalibrationRecord& r = records->front();

  const double exact = std::cbrt(24.0 * kRadius * kLatticeTarget);
  std::printf("V4 square: a0 = %.12e m, exact %.12e m, relative difference %.2e, %d solve(s)\n",
              r.residual_aperture_m, exact, std::abs(r.residual_aperture_m / exact - 1.0),
              r.iterations);
  EXPECT_NEAR(r.residual_aperture_m / exact, 1.0, kLatticeTolerance);
  EXPECT_NEAR(r.first_guess_residual_aperture_m / exact, 1.0, kLatticeTolerance);
  EXPECT_LT(r.first_guess_relative_error, kLatticeTolerance);
  EXPECT_LT(r.relative_error, kLatticeTolerance);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_EQ(r.corrections, 0);

  // The record's packing statistics, exact on a lattice: (n-1)m + n(m-1) contacts, square domains
  // of area 4R^2 holding pi R^2 of solid.
  const double n = columns;
  const double m = rows;
  EXPECT_EQ(r.packing.particle_count, columns * rows);
  EXPECT_EQ(r.packing.contact_count, static_cast<std::size_t>((n - 1) * m + n * (m - 1)));
  EXPECT_DOUBLE_EQ(r.packing.coordination_number, 2.0 * ((n - 1) * m + n * (m - 1)) / (n * m));
  EXPECT_NEAR(r.packing.porosity_2d, 1.0 - M_PI / 4.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.packing.mean_radius_m, kRadius);
  EXPECT_NEAR(r.packing.radius_std_dev_m, 0.0, 1e-12 * kRadius);  // round-off of the mean
  EXPECT_EQ(r.packing.min_radius_m, kRadius);
  EXPECT_EQ(r.packing.max_radius_m, kRadius);
  EXPECT_EQ(r.stress.pipes_in_compression, 0u);
  EXPECT_EQ(r.stress.pipes_open, 0u);
  EXPECT_EQ(r.stress.pipes_closed_unloaded, r.packing.pipe_count);
  EXPECT_TRUE(r.stress.aperture_proportional_to_a0);
  EXPECT_EQ(r.aperture.residual_aperture_m, r.residual_aperture_m);
  EXPECT_EQ(r.flow_axis, FlowAxis::kX);
  EXPECT_EQ(r.pressure_drop_pa, calibration_test::kPressureDrop);

  // The same record as named numbers, sorted by name.
  const auto metrics = CalibrationMetrics(r);
  EXPECT_TRUE(std::is_sorted(metrics.begin(), metrics.end()));
  const auto a0 = std::find_if(metrics.begin(), metrics.end(), [](const auto& entry) {
    return entry.first == "residual_aperture_m";
  });
  ASSERT_NE(a0, metrics.end());
  EXPECT_EQ(a0->second, r.residual_aperture_m);
}

TEST(CalibrationLattice, V4_SquareLatticeAlongY) {
  CalibrationSpec spec = PermeameterSpec(LatticePackingSpec{LatticeKind::kSquare, 12, 25, kRadius});
  spec.scene.boundary.axis = FlowAxis::kY;
  spec.target_permeabilities_m2 = {kLatticeTarget};
  const auto records = CalibrateResidualAperture(spec);
  ASSERT_TRUE(records.ok()) << records.status().ToString();
  const CalibrationRecord& r = records->front();
  EXPECT_NEAR(r.residual_aperture_m / std::cbrt(24.0 * kRadius * kLatticeTarget), 1.0,
              kLatticeTolerance);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_EQ(r.flow_axis, FlowAxis::kY);
}

TEST(CalibrationLattice, V4_HexLatticeAlongX) {
  CalibrationSpec spec = PermeameterSpec(LatticePackingSpec{LatticeKind::kHex, 30, 20, kRadius});
  spec.target_permeabilities_m2 = {kLatticeTarget};
  const auto records = CalibrateResidualAperture(spec);
  ASSERT_TRUE(records.ok()) << records.status().ToString();
  const CalibrationRecord& r = records->front();
  const double exact = std::cbrt(24.0 * std::sqrt(3.0) * kRadius * kLatticeTarget);
  EXPECT_NEAR(r.residual_aperture_m / exact, 1.0, kLatticeTolerance);
  EXPECT_EQ(r.iterations, 1);
}

}  // namespace
}  // namespace seep::core
