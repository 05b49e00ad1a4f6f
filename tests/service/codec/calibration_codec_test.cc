// seep.v1.Calibration -> core::CalibrationSpec: defaults, the packing of an earlier job, the
// setup hash, and calibrations invalid in one field each, rejected with INVALID_ARGUMENT and a
// message that starts with the field's path.
#include "codec/calibration_codec.h"

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <functional>
#include <ostream>
#include <string>

namespace seep::service {
namespace {

v1::Calibration ValidCalibration() {
  v1::Calibration c;
  const bool ok = google::protobuf::TextFormat::ParseFromString(
      R"pb(
        name: "ok"
        scene {
          packing { lattice { kind: LATTICE_KIND_SQUARE columns: 6 rows: 4 radius_m: 1e-3 } }
          fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
          aperture { reference_force_n: 10 gap_multiplier: 0.5 }
          boundary { axis: FLOW_AXIS_Y inlet_pressure_pa: 2e5 outlet_pressure_pa: 1e5 }
        }
        stress {
          uniform_normal_force_n: 5
          contact_forces { particle_i: 0 particle_j: 1 normal_force_n: 7 }
        }
        target_permeabilities_m2: [ 1e-13, 3e-13, 1e-12 ]
        tags: "a"
        tags: "b"
      )pb",
      &c);
  EXPECT_TRUE(ok);
  return c;
}

TEST(CalibrationCodec, ConvertsAValidCalibrationWithDefaults) {
  auto spec = CalibrationFromProto(ValidCalibration());
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  EXPECT_EQ(spec->target_permeabilities_m2, (std::vector<double>{1e-13, 3e-13, 1e-12}));
  EXPECT_EQ(spec->tolerance, 1e-6);  // 0 on the wire = the default
  EXPECT_EQ(spec->max_iterations, 30);
  EXPECT_EQ(spec->scene.boundary.axis, core::FlowAxis::kY);
  EXPECT_EQ(spec->scene.boundary.inlet_pressure_pa, 2e5);
  EXPECT_EQ(spec->scene.aperture.reference_force_n, 10.0);
  EXPECT_EQ(spec->scene.aperture.residual_aperture_m, 0.0);  // the unknown
  EXPECT_EQ(spec->stress.uniform_normal_force_n, 5.0);
  ASSERT_EQ(spec->stress.contact_forces.size(), 1u);
  EXPECT_EQ(spec->stress.contact_forces[0].particle_j, 1);
  EXPECT_EQ(spec->stress.contact_forces[0].normal_force_n, 7.0);

  v1::Calibration set = ValidCalibration();
  set.set_tolerance(1e-9);
  set.set_max_iterations(12);
  spec = CalibrationFromProto(set);
  ASSERT_TRUE(spec.ok());
  EXPECT_EQ(spec->tolerance, 1e-9);
  EXPECT_EQ(spec->max_iterations, 12);
}

struct BadCalibration {
  const char* name;
  std::function<void(v1::Calibration&)> mutate;
  const char* field;  // the message must start with "<field>:"
};

void PrintTo(const BadCalibration& bad, std::ostream* os) { *os << bad.name; }

class BadCalibrations : public ::testing::TestWithParam<BadCalibration> {};

TEST_P(BadCalibrations, AreRejectedNamingTheField) {
  v1::Calibration c = ValidCalibration();
  GetParam().mutate(c);
  // As SubmitJob does: the request's checks, then the decode and validation.
  core::Status status = CheckCalibrationRequest(c);
  if (status.ok()) status = CalibrationFromProto(c).status();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), core::StatusCode::kInvalidArgument) << status.ToString();
  EXPECT_EQ(status.message().rfind(std::string(GetParam().field) + ":", 0), 0u) << status.message();
}

INSTANTIATE_TEST_SUITE_P(
    CalibrationCodec, BadCalibrations,
    ::testing::Values(
        BadCalibration{"NoScene", [](v1::Calibration& c) { c.clear_scene(); }, "calibration.scene"},
        BadCalibration{"NoTargets", [](v1::Calibration& c) { c.clear_target_permeabilities_m2(); },
                       "calibration.target_permeabilities_m2"},
        BadCalibration{"NegativeThirdTarget",
                       [](v1::Calibration& c) { c.set_target_permeabilities_m2(2, -1.0); },
                       "calibration.target_permeabilities_m2[2]"},
        BadCalibration{"ToleranceOfOne", [](v1::Calibration& c) { c.set_tolerance(1.0); },
                       "calibration.tolerance"},
        BadCalibration{"TooManyIterations", [](v1::Calibration& c) { c.set_max_iterations(5000); },
                       "calibration.max_iterations"},
        BadCalibration{
            "NoPackingNoEarlierJob",
            [](v1::Calibration& c) { c.mutable_scene()->mutable_packing()->clear_lattice(); },
            "calibration.scene.packing"},
        BadCalibration{"PackingAndEarlierJob", [](v1::Calibration& c) { c.set_from_job_id("j-1"); },
                       "calibration.from_job_id"},
        BadCalibration{
            "ZeroViscosity",
            [](v1::Calibration& c) { c.mutable_scene()->mutable_fluid()->set_viscosity_pa_s(0.0); },
            "calibration.scene.fluid.viscosity_pa_s"},
        BadCalibration{
            "NoAxis",
            [](v1::Calibration& c) { c.mutable_scene()->mutable_boundary()->clear_axis(); },
            "calibration.scene.boundary.axis"},
        BadCalibration{"RadialBoundary",
                       [](v1::Calibration& c) {
                         auto* b = c.mutable_scene()->mutable_boundary();
                         b->Clear();
                         b->mutable_radial()->set_well_radius_m(2e-3);
                         b->mutable_radial()->set_outer_radius_m(4e-3);
                         b->mutable_radial()->set_well_pressure_pa(1e5);
                       },
                       "calibration.scene.boundary.radial"},
        BadCalibration{"NoPressureDrop",
                       [](v1::Calibration& c) {
                         c.mutable_scene()->mutable_boundary()->set_outlet_pressure_pa(2e5);
                       },
                       "calibration.scene.boundary.outlet_pressure_pa"},
        BadCalibration{"ContactWithItself",
                       [](v1::Calibration& c) {
                         c.mutable_stress()->mutable_contact_forces(0)->set_particle_j(0);
                       },
                       "calibration.stress.contact_forces[0]"},
        BadCalibration{"RepeatedTag", [](v1::Calibration& c) { c.add_tags("a"); },
                       "calibration.tags[2]"},
        BadCalibration{"TagWithASpace", [](v1::Calibration& c) { c.set_tags(1, "two words"); },
                       "calibration.tags[1]"}),
    [](const ::testing::TestParamInfo<BadCalibration>& p) { return p.param.name; });

TEST(CalibrationCodec, TakesThePackingOfAnEarlierJob) {
  v1::Scene earlier_scene;
  earlier_scene.mutable_packing()->mutable_random()->set_seed(9);
  earlier_scene.mutable_packing()->set_contact_gap_m(1e-5);
  JobRecord earlier;
  earlier.id = "j-old";
  earlier.kind = JobKind::kSimulation;
  ASSERT_TRUE(earlier_scene.SerializeToString(&earlier.scene));

  v1::Calibration c = ValidCalibration();
  c.mutable_scene()->mutable_packing()->clear_lattice();
  c.set_from_job_id("j-old");
  ASSERT_TRUE(CheckCalibrationRequest(c).ok());
  ASSERT_TRUE(ResolvePackingFrom(earlier, &c).ok());
  EXPECT_EQ(c.scene().packing().random().seed(), 9u);
  EXPECT_EQ(c.scene().packing().contact_gap_m(), 1e-5);

  // A contact gap given in the calibration wins; a calibration job is a source too.
  v1::Calibration again = ValidCalibration();
  again.mutable_scene()->mutable_packing()->clear_lattice();
  again.mutable_scene()->mutable_packing()->set_contact_gap_m(3e-5);
  JobRecord earlier_calibration;
  earlier_calibration.kind = JobKind::kCalibration;
  ASSERT_TRUE(c.SerializeToString(&earlier_calibration.scene));
  ASSERT_TRUE(ResolvePackingFrom(earlier_calibration, &again).ok());
  EXPECT_EQ(again.scene().packing().random().seed(), 9u);
  EXPECT_EQ(again.scene().packing().contact_gap_m(), 3e-5);

  earlier.scene = "\xff\xff";
  EXPECT_EQ(ResolvePackingFrom(earlier, &again).code(), core::StatusCode::kFailedPrecondition);
}

TEST(CalibrationCodec, SetupHashIgnoresTargetsNameAndTagsButNotTheStress) {
  const v1::Calibration base = ValidCalibration();
  const std::string hash = CalibrationSetupSha256(base);
  EXPECT_EQ(hash.size(), 64u);
  v1::Calibration other = base;
  other.set_name("another");
  other.clear_target_permeabilities_m2();
  other.add_target_permeabilities_m2(5e-14);
  other.add_tags("c");
  other.set_tolerance(1e-8);
  other.mutable_scene()->mutable_aperture()->set_residual_aperture_m(3e-5);  // ignored input
  EXPECT_EQ(CalibrationSetupSha256(other), hash);
  other.mutable_stress()->set_uniform_normal_force_n(6);
  EXPECT_NE(CalibrationSetupSha256(other), hash);
}

TEST(CalibrationCodec, RecordToProtoCarriesEveryPart) {
  StoredCalibration s;
  s.job_id = "j-1";
  s.record.target_index = 3;
  s.record.target_permeability_m2 = 1e-13;
  s.record.residual_aperture_m = 2e-5;
  s.record.iterations = 2;
  s.record.packing.particle_count = 300;
  s.record.packing.porosity_2d = 0.2;
  s.record.aperture.reference_force_n = 10;
  s.record.stress.pipes_in_compression = 7;
  s.record.flow_axis = core::FlowAxis::kY;
  s.tolerance = 1e-6;
  s.scene_sha256 = "abc";
  s.created_at_ms = 1500;
  s.tags = {"x"};
  v1::CalibrationRecord out;
  CalibrationRecordToProto(s, &out);
  EXPECT_EQ(out.job_id(), "j-1");
  EXPECT_EQ(out.target_index(), 3u);
  EXPECT_EQ(out.aperture().residual_aperture_m(), 2e-5);
  EXPECT_EQ(out.aperture().reference_force_n(), 10.0);
  EXPECT_EQ(out.packing().particle_count(), 300u);
  EXPECT_EQ(out.stress().pipes_in_compression(), 7u);
  EXPECT_EQ(out.flow_axis(), v1::FLOW_AXIS_Y);
  EXPECT_EQ(out.created_at().seconds(), 1);
  EXPECT_EQ(out.created_at().nanos(), 500000000);
  ASSERT_EQ(out.tags_size(), 1);
  EXPECT_EQ(out.tags(0), "x");
}

}  // namespace
}  // namespace seep::service
