// Bad calibration specs are INVALID_ARGUMENT with the failing field's path in the message.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "calibration_test_scenes.h"
#include "seep/core/calibration/calibration.h"

namespace seep::core {
namespace {

using calibration_test::PermeameterSpec;

CalibrationSpec GoodSpec() {
  CalibrationSpec spec = PermeameterSpec(LatticePackingSpec{LatticeKind::kSquare, 6, 5, 1e-3});
  spec.target_permeabilities_m2 = {1e-13, 2e-13, 3e-13};
  return spec;
}

void ExpectInvalid(const Status& status, const std::string& field) {
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << status.ToString();
  EXPECT_EQ(status.message().rfind(field + ":", 0), 0u)
      << "expected the message to start with '" << field << ":', got " << status.message();
}

TEST(CalibrationValidation, GoodSpecPasses) {
  EXPECT_TRUE(ValidateCalibration(GoodSpec()).ok());
  // a0 is the result: whatever the scene holds there is ignored.
  CalibrationSpec spec = GoodSpec();
  spec.scene.aperture.residual_aperture_m = -1.0;
  EXPECT_TRUE(ValidateCalibration(spec).ok());
}

TEST(CalibrationValidation, TargetsNameTheirIndex) {
  CalibrationSpec spec = GoodSpec();
  spec.target_permeabilities_m2[2] = -1.0;
  const Status s = ValidateCalibration(spec);
  ExpectInvalid(s, "calibration.target_permeabilities_m2[2]");
  EXPECT_NE(s.message().find("got -1"), std::string::npos) << s.message();

  spec.target_permeabilities_m2[2] = std::numeric_limits<double>::quiet_NaN();
  ExpectInvalid(ValidateCalibration(spec), "calibration.target_permeabilities_m2[2]");
  spec.target_permeabilities_m2 = {};
  ExpectInvalid(ValidateCalibration(spec), "calibration.target_permeabilities_m2");
}

TEST(CalibrationValidation, ToleranceAndIterations) {
  CalibrationSpec spec = GoodSpec();
  spec.tolerance = 0.0;
  ExpectInvalid(ValidateCalibration(spec), "calibration.tolerance");
  spec.tolerance = 1e-15;
  ExpectInvalid(ValidateCalibration(spec), "calibration.tolerance");
  spec = GoodSpec();
  spec.max_iterations = 0;
  ExpectInvalid(ValidateCalibration(spec), "calibration.max_iterations");
}

TEST(CalibrationValidation, SceneFieldsArePrefixed) {
  CalibrationSpec spec = GoodSpec();
  spec.scene.fluid.viscosity_pa_s = -1.0;
  ExpectInvalid(ValidateCalibration(spec), "calibration.scene.fluid.viscosity_pa_s");
  spec = GoodSpec();
  spec.scene.boundary.radial = RadialBoundarySpec{1e-3, 4e-3, 1e5, 0.0};
  ExpectInvalid(ValidateCalibration(spec), "calibration.scene.boundary.radial");
  spec = GoodSpec();
  spec.scene.boundary.outlet_pressure_pa = spec.scene.boundary.inlet_pressure_pa;
  ExpectInvalid(ValidateCalibration(spec), "calibration.scene.boundary.outlet_pressure_pa");
}

TEST(CalibrationValidation, StressFields) {
  CalibrationSpec spec = GoodSpec();
  spec.stress.uniform_normal_force_n = std::numeric_limits<double>::infinity();
  ExpectInvalid(ValidateCalibration(spec), "calibration.stress.uniform_normal_force_n");

  spec = GoodSpec();
  spec.stress.contact_forces = {{0, 1, 1.0}, {2, 2, 1.0}};
  ExpectInvalid(ValidateCalibration(spec), "calibration.stress.contact_forces[1]");
  spec.stress.contact_forces = {{0, 1, 1.0}, {1, 0, 2.0}};
  ExpectInvalid(ValidateCalibration(spec), "calibration.stress.contact_forces[1]");
  spec.stress.contact_forces = {{0, 1, std::numeric_limits<double>::quiet_NaN()}};
  ExpectInvalid(ValidateCalibration(spec), "calibration.stress.contact_forces[0].normal_force_n");

  // A compressive force needs F0 > 0 to give an aperture.
  spec.stress.contact_forces = {{0, 1, 1.0}};
  spec.scene.aperture.reference_force_n = 0.0;
  ExpectInvalid(ValidateCalibration(spec), "calibration.scene.aperture.reference_force_n");
}

TEST(CalibrationValidation, ContactForcesAreCheckedAgainstThePacking) {
  CalibrationSpec spec = GoodSpec();  // 6 x 5 square lattice: particle id = row * 6 + column
  spec.stress.contact_forces = {{0, 1, 1.0}, {0, 99, 1.0}};
  ExpectInvalid(Calibrator::Create(spec).status(), "calibration.stress.contact_forces[1]");
  spec.stress.contact_forces = {{0, 1, 1.0}, {0, 7, 1.0}};  // diagonal neighbours: no contact
  const Status s = Calibrator::Create(spec).status();
  ExpectInvalid(s, "calibration.stress.contact_forces[1]");
  EXPECT_NE(s.message().find("not in contact"), std::string::npos) << s.message();
  // The sweep reports the same.
  ExpectInvalid(CalibrateResidualAperture(spec).status(), "calibration.stress.contact_forces[1]");
}

}  // namespace
}  // namespace seep::core
