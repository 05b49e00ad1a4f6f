#include "codec/scene_codec.h"

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <ostream>

namespace seep::service {
namespace {

v1::Scene ValidScene() {
  v1::Scene scene;
  const bool ok = google::protobuf::TextFormat::ParseFromString(
      R"pb(
        name: "ok"
        packing { lattice { kind: LATTICE_KIND_SQUARE columns: 4 rows: 3 radius_m: 1e-3 } }
        fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2e9 }
        aperture { residual_aperture_m: 1e-5 reference_force_n: 10 gap_multiplier: 0.5 }
        boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
        solver {
          kind: SOLVER_KIND_IMPLICIT
          storage: STORAGE_VOLUME_PORE
          dt_factor: 10
          end_time_s: 1
        }
      )pb",
      &scene);
  EXPECT_TRUE(ok);
  return scene;
}

TEST(SceneCodec, ConvertsAValidScene) {
  auto spec = SceneFromProto(ValidScene());
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  const auto& lattice = std::get<core::LatticePackingSpec>(spec->packing.source);
  EXPECT_EQ(lattice.columns, 4u);
  EXPECT_EQ(lattice.rows, 3u);
  EXPECT_DOUBLE_EQ(lattice.radius_m, 1e-3);
  EXPECT_EQ(spec->solver.kind, core::SolverKind::kImplicit);
  EXPECT_EQ(spec->solver.storage, core::StorageVolumeKind::kPore);
  EXPECT_DOUBLE_EQ(spec->aperture.gap_multiplier, 0.5);
  EXPECT_DOUBLE_EQ(spec->boundary.inlet_pressure_pa, 1e5);
}

struct BadScene {
  const char* name;  // the test name suffix
  std::function<void(v1::Scene&)> mutate;
  const char* field;  // the message must start with this path
};

// Keeps CTest's test names readable (gtest prints the parameter into the listing).
void PrintTo(const BadScene& bad, std::ostream* os) { *os << bad.name; }

class SceneCodecRejects : public ::testing::TestWithParam<BadScene> {};

TEST_P(SceneCodecRejects, NamesTheField) {
  v1::Scene scene = ValidScene();
  GetParam().mutate(scene);
  auto spec = SceneFromProto(scene);
  ASSERT_FALSE(spec.ok()) << GetParam().name;
  EXPECT_EQ(spec.status().code(), core::StatusCode::kInvalidArgument);
  EXPECT_EQ(spec.status().message().rfind(GetParam().field, 0), 0u)
      << "message: " << spec.status().message();
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

INSTANTIATE_TEST_SUITE_P(
    BadScenes, SceneCodecRejects,
    ::testing::Values(
        BadScene{"NoPacking", [](v1::Scene& s) { s.clear_packing(); }, "scene.packing:"},
        BadScene{"LatticeKindUnset",
                 [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->clear_kind(); },
                 "scene.packing.lattice.kind:"},
        BadScene{"OneColumn",
                 [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->set_columns(1); },
                 "scene.packing.lattice.columns:"},
        BadScene{"NoRows",
                 [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->set_rows(0); },
                 "scene.packing.lattice.rows:"},
        BadScene{"NegativeRadius",
                 [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->set_radius_m(-1); },
                 "scene.packing.lattice.radius_m:"},
        BadScene{"NaNRadius",
                 [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->set_radius_m(kNaN); },
                 "scene.packing.lattice.radius_m:"},
        BadScene{"HugeLattice",
                 [](v1::Scene& s) {
                   s.mutable_packing()->mutable_lattice()->set_columns(100000);
                   s.mutable_packing()->mutable_lattice()->set_rows(100000);
                 },
                 "scene.packing.lattice:"},
        BadScene{"ParticleArraysOfUnequalLength",
                 [](v1::Scene& s) {
                   auto* p = s.mutable_packing()->mutable_particles();
                   for (int i = 0; i < 3; ++i) {
                     p->add_x_m(i);
                     p->add_y_m(0);
                     p->add_radius_m(0.5);
                   }
                   p->add_x_m(4);
                 },
                 "scene.packing.particles:"},
        BadScene{"ParticleWithZeroRadius",
                 [](v1::Scene& s) {
                   auto* p = s.mutable_packing()->mutable_particles();
                   for (int i = 0; i < 3; ++i) {
                     p->add_x_m(i);
                     p->add_y_m(0);
                     p->add_radius_m(i == 2 ? 0.0 : 0.5);
                   }
                 },
                 "scene.packing.particles[2].radius_m:"},
        BadScene{"RandomPorosityAboveOne",
                 [](v1::Scene& s) {
                   auto* r = s.mutable_packing()->mutable_random();
                   r->set_width_m(1);
                   r->set_height_m(1);
                   r->set_min_radius_m(0.01);
                   r->set_max_radius_m(0.02);
                   r->set_particle_count(100);
                   r->set_target_porosity(1.5);
                 },
                 "scene.packing.random.target_porosity:"},
        BadScene{"RandomRadiiSwapped",
                 [](v1::Scene& s) {
                   auto* r = s.mutable_packing()->mutable_random();
                   r->set_width_m(1);
                   r->set_height_m(1);
                   r->set_min_radius_m(0.02);
                   r->set_max_radius_m(0.01);
                   r->set_particle_count(100);
                   r->set_target_porosity(0.2);
                 },
                 "scene.packing.random.max_radius_m:"},
        BadScene{"RandomWithoutTarget",
                 [](v1::Scene& s) {
                   auto* r = s.mutable_packing()->mutable_random();
                   r->set_width_m(1);
                   r->set_height_m(1);
                   r->set_min_radius_m(0.01);
                   r->set_max_radius_m(0.02);
                   r->set_particle_count(100);
                 },
                 "scene.packing.random.target:"},
        BadScene{"NegativeContactGap",
                 [](v1::Scene& s) { s.mutable_packing()->set_contact_gap_m(-1); },
                 "scene.packing.contact_gap_m:"},
        BadScene{"ZeroViscosity", [](v1::Scene& s) { s.mutable_fluid()->set_viscosity_pa_s(0); },
                 "scene.fluid.viscosity_pa_s:"},
        BadScene{"InfiniteBulkModulus",
                 [](v1::Scene& s) { s.mutable_fluid()->set_bulk_modulus_pa(kInf); },
                 "scene.fluid.bulk_modulus_pa:"},
        BadScene{"NoResidualAperture",
                 [](v1::Scene& s) { s.mutable_aperture()->set_residual_aperture_m(0); },
                 "scene.aperture.residual_aperture_m:"},
        BadScene{"NegativeGapMultiplier",
                 [](v1::Scene& s) { s.mutable_aperture()->set_gap_multiplier(-0.1); },
                 "scene.aperture.gap_multiplier:"},
        BadScene{"CapBelowA0", [](v1::Scene& s) { s.mutable_aperture()->set_max_aperture_m(1e-6); },
                 "scene.aperture.max_aperture_m:"},
        BadScene{"AxisUnset", [](v1::Scene& s) { s.mutable_boundary()->clear_axis(); },
                 "scene.boundary.axis:"},
        BadScene{"NaNInletPressure",
                 [](v1::Scene& s) { s.mutable_boundary()->set_inlet_pressure_pa(kNaN); },
                 "scene.boundary.inlet_pressure_pa:"},
        BadScene{"SolverKindUnset", [](v1::Scene& s) { s.mutable_solver()->clear_kind(); },
                 "scene.solver.kind:"},
        BadScene{"TransientWithoutStorage",
                 [](v1::Scene& s) { s.mutable_solver()->clear_storage(); },
                 "scene.solver.storage:"},
        BadScene{"NoEndTime", [](v1::Scene& s) { s.mutable_solver()->set_end_time_s(0); },
                 "scene.solver.end_time_s:"},
        BadScene{"ExplicitAboveTheCriticalStep",
                 [](v1::Scene& s) {
                   s.mutable_solver()->set_kind(v1::SOLVER_KIND_EXPLICIT);
                   s.mutable_solver()->set_dt_factor(1.5);
                 },
                 "scene.solver.dt_factor:"}),
    [](const ::testing::TestParamInfo<BadScene>& param_info) {
      return std::string(param_info.param.name);
    });

}  // namespace
}  // namespace seep::service
