#include "codec/scene_codec.h"

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "bad_scenes.h"
#include "codec/state_size_estimate.h"
#include "seep/core/run/simulation.h"

namespace seep::service {
namespace {

using testing::BadScene;

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
  EXPECT_EQ(spec->solver.storage, core::StorageVolume::kPore);
  EXPECT_DOUBLE_EQ(spec->aperture.gap_multiplier, 0.5);
  EXPECT_DOUBLE_EQ(spec->boundary.inlet_pressure_pa, 1e5);
}

// A wall given by its end points and a velocity keeps them through the codec; a side wall stays
// a side wall without either.
TEST(SceneCodec, ConvertsSegmentAndVelocityControlledWalls) {
  v1::Scene scene = ValidScene();
  ASSERT_TRUE(google::protobuf::TextFormat::MergeFromString(
      R"pb(
        effects {
          contacts {
            law { kn_n_per_m: 1e7 damping: NORMAL_DAMPING_CRITICAL_RATIO }
            density_kg_m3: 2650
          }
        }
        effects {
          walls {
            walls { x0_m: -0.01 y0_m: 0.002 x1_m: 0.03 y1_m: -0.001 normal_velocity_m_s: -0.25 }
            walls { side: WALL_SIDE_TOP servo_stress_pa: 1e5 servo_max_speed_m_s: 0.1 }
          }
        }
      )pb",
      &scene));
  auto spec = SceneFromProto(scene);
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  const auto& walls = std::get<core::WallsEffectSpec>(spec->effects[1]).walls;
  ASSERT_EQ(walls.size(), 2u);
  ASSERT_TRUE(walls[0].segment.has_value());
  EXPECT_EQ(walls[0].segment->x0_m, -0.01);
  EXPECT_EQ(walls[0].segment->y0_m, 0.002);
  EXPECT_EQ(walls[0].segment->x1_m, 0.03);
  EXPECT_EQ(walls[0].segment->y1_m, -0.001);
  ASSERT_TRUE(walls[0].normal_velocity_m_s.has_value());
  EXPECT_EQ(*walls[0].normal_velocity_m_s, -0.25);
  EXPECT_EQ(walls[0].servo_stress_pa, 0.0);
  EXPECT_FALSE(walls[1].segment.has_value());
  EXPECT_FALSE(walls[1].normal_velocity_m_s.has_value());
  EXPECT_EQ(walls[1].side, core::WallSide::kTop);
  EXPECT_EQ(walls[1].servo_stress_pa, 1e5);
  EXPECT_EQ(core::WallName(walls[0], 0), "segment0");
  EXPECT_EQ(core::WallName(walls[1], 1), "top");
}

// Two stages through the codec: settings given as a constant or a schedule, settings left unset,
// every wall mode (fixed: false counting as unset) and every kind of end condition. DecodeScene
// only: what the values mean is core's validation.
TEST(SceneCodec, ConvertsStages) {
  v1::Scene scene = ValidScene();
  ASSERT_TRUE(google::protobuf::TextFormat::MergeFromString(
      R"pb(
        stages {
          name: "confine"
          local_damping_alpha: 0.7
          walls {
            wall: 0
            servo_stress_pa { value: 1e6 }
          }
          walls {
            wall: 1
            normal_velocity_m_s {
              schedule {
                time_s: [ 0, 0.5 ]
                value: [ 0, -0.01 ]
              }
            }
            drain_pressure_pa { value: 2e5 }
          }
          walls { wall: 2 fixed: true }
          walls { wall: 3 fixed: false }
          end { servo_held { tolerance_fraction: 0.02 hold_s: 1e-3 } }
          end { kinetic_energy_ratio: 1e-4 }
          end { steps: 50000 }
          max_duration_s: 2
          continue_at_max_duration: true
        }
        stages {
          name: "inject"
          injection_rate_m2_s {
            schedule {
              time_s: [ 0, 1, 2 ]
              value: [ 0, 1e-5, 2e-5 ]
            }
          }
          inlet_pressure_pa { value: 3e5 }
          outlet_pressure_pa { value: 0 }
          end { duration_s: 5 }
          end { bonds_broken: 10 }
          end { breakthrough: true }
          end { well_pressure_past_peak: 0.3 }
        }
      )pb",
      &scene));
  auto spec = DecodeScene(scene);
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  ASSERT_EQ(spec->stages.size(), 2u);

  const core::StageSpec& confine = spec->stages[0];
  EXPECT_EQ(confine.name, "confine");
  EXPECT_EQ(confine.local_damping_alpha, std::optional<double>(0.7));
  EXPECT_FALSE(confine.injection_rate_m2_s.has_value());
  EXPECT_FALSE(confine.inlet_pressure_pa.has_value());
  EXPECT_FALSE(confine.well_pressure_pa.has_value());
  ASSERT_EQ(confine.walls.size(), 4u);
  EXPECT_EQ(confine.walls[0].wall, 0u);
  ASSERT_TRUE(confine.walls[0].servo_stress_pa.has_value());
  EXPECT_EQ(std::get<double>(*confine.walls[0].servo_stress_pa), 1e6);
  EXPECT_FALSE(confine.walls[0].normal_velocity_m_s.has_value());
  EXPECT_FALSE(confine.walls[0].drain_pressure_pa.has_value());
  ASSERT_TRUE(confine.walls[1].normal_velocity_m_s.has_value());
  const auto& velocity = std::get<core::ScheduleSpec>(*confine.walls[1].normal_velocity_m_s);
  EXPECT_EQ(velocity.time_s, (std::vector<double>{0.0, 0.5}));
  EXPECT_EQ(velocity.value, (std::vector<double>{0.0, -0.01}));
  ASSERT_TRUE(confine.walls[1].drain_pressure_pa.has_value());
  EXPECT_EQ(std::get<double>(*confine.walls[1].drain_pressure_pa), 2e5);
  EXPECT_TRUE(confine.walls[2].fixed);
  EXPECT_EQ(confine.walls[3].wall, 3u);
  EXPECT_FALSE(confine.walls[3].fixed);
  EXPECT_FALSE(confine.walls[3].servo_stress_pa.has_value());
  EXPECT_FALSE(confine.walls[3].normal_velocity_m_s.has_value());
  ASSERT_EQ(confine.end.size(), 3u);
  const auto& held = std::get<core::ServoHeldEnd>(confine.end[0]);
  EXPECT_EQ(held.tolerance_fraction, 0.02);
  EXPECT_EQ(held.hold_s, 1e-3);
  EXPECT_EQ(std::get<core::KineticEnergyEnd>(confine.end[1]).ratio, 1e-4);
  EXPECT_EQ(std::get<core::StepsEnd>(confine.end[2]).steps, 50000u);
  EXPECT_EQ(confine.max_duration_s, 2.0);
  EXPECT_TRUE(confine.continue_at_max_duration);

  const core::StageSpec& inject = spec->stages[1];
  EXPECT_EQ(inject.name, "inject");
  EXPECT_FALSE(inject.local_damping_alpha.has_value());
  ASSERT_TRUE(inject.injection_rate_m2_s.has_value());
  const auto& rate = std::get<core::ScheduleSpec>(*inject.injection_rate_m2_s);
  EXPECT_EQ(rate.time_s, (std::vector<double>{0.0, 1.0, 2.0}));
  EXPECT_EQ(rate.value, (std::vector<double>{0.0, 1e-5, 2e-5}));
  ASSERT_TRUE(inject.inlet_pressure_pa.has_value());
  EXPECT_EQ(std::get<double>(*inject.inlet_pressure_pa), 3e5);
  // A constant 0 given is a setting (to 0), not an unset one.
  ASSERT_TRUE(inject.outlet_pressure_pa.has_value());
  EXPECT_EQ(std::get<double>(*inject.outlet_pressure_pa), 0.0);
  EXPECT_FALSE(inject.outer_pressure_pa.has_value());
  EXPECT_TRUE(inject.walls.empty());
  ASSERT_EQ(inject.end.size(), 4u);
  EXPECT_EQ(std::get<core::DurationEnd>(inject.end[0]).duration_s, 5.0);
  EXPECT_EQ(std::get<core::BondsBrokenEnd>(inject.end[1]).count, 10u);
  EXPECT_TRUE(std::holds_alternative<core::BreakthroughEnd>(inject.end[2]));
  EXPECT_EQ(std::get<core::WellPressurePastPeakEnd>(inject.end[3]).fraction, 0.3);
  EXPECT_EQ(inject.max_duration_s, 0.0);
  EXPECT_FALSE(inject.continue_at_max_duration);

  EXPECT_TRUE(DecodeScene(ValidScene())->stages.empty());
}

// Turns the valid scene into a valid radial one.
void MakeRadial(v1::Scene& scene) {
  auto* b = scene.mutable_boundary();
  b->clear_axis();
  b->clear_inlet_pressure_pa();
  auto* radial = b->mutable_radial();
  radial->set_well_radius_m(3e-3);
  radial->set_outer_radius_m(2e-2);
  radial->set_well_pressure_pa(2e5);
  radial->set_outer_pressure_pa(1e5);
}

TEST(SceneCodec, ConvertsARadialBoundary) {
  v1::Scene scene = ValidScene();
  MakeRadial(scene);
  auto spec = SceneFromProto(scene);
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  ASSERT_TRUE(spec->boundary.radial.has_value());
  EXPECT_DOUBLE_EQ(spec->boundary.radial->well_radius_m, 3e-3);
  EXPECT_DOUBLE_EQ(spec->boundary.radial->outer_radius_m, 2e-2);
  EXPECT_DOUBLE_EQ(spec->boundary.radial->well_pressure_pa, 2e5);
  EXPECT_DOUBLE_EQ(spec->boundary.radial->outer_pressure_pa, 1e5);
  EXPECT_FALSE(SceneFromProto(ValidScene())->boundary.radial.has_value());
}

// An unset storage factor is 1 (every volume stores fluid); a set one is taken as written.
TEST(SceneCodec, StorageFactorDefaultsToOne) {
  v1::Scene scene = ValidScene();
  EXPECT_EQ(SceneFromProto(scene)->solver.storage_factor, 1.0);
  scene.mutable_solver()->set_storage_factor(0.25);
  EXPECT_EQ(SceneFromProto(scene)->solver.storage_factor, 0.25);
}

// A DEM-only scene (contacts, no flow) gives what the DEM uses and nothing of the fluid, the
// apertures or the flow solver: it converts and runs; the same scene with flow is refused for the
// solver fields flow needs.
TEST(SceneCodec, ADemOnlySceneNeedsNoFlowSettings) {
  v1::Scene scene;
  ASSERT_TRUE(google::protobuf::TextFormat::ParseFromString(
      R"pb(
        name: "dem only"
        packing { lattice { kind: LATTICE_KIND_HEX columns: 4 rows: 4 radius_m: 1e-3 } }
        solver { end_time_s: 1e-4 }
        effects {
          contacts {
            law {
              kn_n_per_m: 1e7
              kt_n_per_m: 5e6
              friction: 0.5
              damping: NORMAL_DAMPING_CRITICAL_RATIO
              damping_ratio: 0.3
            }
            density_kg_m3: 2650
          }
        }
        effects { gravity { gy_m_s2: -9.81 } }
      )pb",
      &scene));
  auto spec = SceneFromProto(scene);
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  auto sim = core::Simulation::Create(*spec);
  ASSERT_TRUE(sim.ok()) << sim.status().ToString();
  EXPECT_TRUE(sim->Run({}).ok());
  // A value given must still be in range, flow or not.
  scene.mutable_fluid()->set_viscosity_pa_s(-1.0);
  const auto negative = SceneFromProto(scene);
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.status().message().find("scene.fluid.viscosity_pa_s"), std::string::npos);
  scene.mutable_fluid()->clear_viscosity_pa_s();
  scene.add_effects()->mutable_flow();
  const auto with_flow = SceneFromProto(scene);
  ASSERT_FALSE(with_flow.ok());
  EXPECT_NE(with_flow.status().message().find("scene.solver."), std::string::npos)
      << with_flow.status().message();
}

// The scenes shipped in examples/ parse and pass validation.
// Unset keeps CHOLMOD supernodal, the factorization of every scene before the choice existed (a
// scene's results depend on it); each value maps to its kind.
TEST(SceneCodec, LinearSolverDefaultsToSupernodalAndMapsEachChoice) {
  v1::Scene scene = ValidScene();
  EXPECT_EQ(SceneFromProto(scene)->solver.linear_solver,
            core::LinearSolverKind::kCholmodSupernodal);
  const std::pair<v1::LinearSolver, core::LinearSolverKind> choices[] = {
      {v1::LINEAR_SOLVER_CHOLMOD_SUPERNODAL, core::LinearSolverKind::kCholmodSupernodal},
      {v1::LINEAR_SOLVER_SIMPLICIAL_LDLT, core::LinearSolverKind::kEigenSimplicialLdlt},
      {v1::LINEAR_SOLVER_AUTO, core::LinearSolverKind::kAuto}};
  for (const auto& [wire, kind] : choices) {
    scene.mutable_solver()->set_linear_solver(wire);
    EXPECT_EQ(SceneFromProto(scene)->solver.linear_solver, kind) << v1::LinearSolver_Name(wire);
  }
}

TEST(SceneCodec, ConvertsTheExampleScenes) {
  const std::filesystem::path examples = SEEP_EXAMPLES_DIR;
  for (const char* name : {"darcy_square_lattice.textproto", "darcy_random_packing.textproto",
                           "thiem_radial.textproto"}) {
    SCOPED_TRACE(name);
    std::ifstream in(examples / name);
    ASSERT_TRUE(in.good()) << (examples / name);
    std::stringstream text;
    text << in.rdbuf();
    v1::Scene scene;
    ASSERT_TRUE(google::protobuf::TextFormat::ParseFromString(text.str(), &scene));
    auto spec = SceneFromProto(scene);
    ASSERT_TRUE(spec.ok()) << spec.status().ToString();
    EXPECT_EQ(spec->boundary.radial.has_value(), std::string(name) == "thiem_radial.textproto");
  }
}

TEST(SceneCodec, ProgressIntervalBeyondTheLimitIsNamed) {
  v1::Scene scene = ValidScene();
  scene.mutable_solver()->set_progress_every(1);  // any small interval is fine
  EXPECT_TRUE(SceneFromProto(scene).ok());
  scene.mutable_solver()->set_progress_every(std::uint64_t{1} << 40);
  auto spec = SceneFromProto(scene);
  ASSERT_FALSE(spec.ok());
  EXPECT_EQ(spec.status().code(), core::StatusCode::kInvalidArgument);
  EXPECT_EQ(spec.status().message().rfind("scene.solver.progress_every: at most 1000000000", 0), 0u)
      << spec.status().message();
}

// A lattice whose particles move: 12 million disks would need more than protobuf's 2 GiB per
// checkpoint, so the scene is refused at submit with the figures; 1 million fit.
TEST(SceneCodec, StateThatCannotBeCheckpointedIsRefusedWithTheNumbers) {
  v1::Scene scene = ValidScene();
  auto* law = scene.add_effects()->mutable_contacts()->mutable_law();
  law->set_kn_n_per_m(1e8);
  law->set_kt_n_per_m(5e7);
  law->set_friction(0.5);
  law->set_damping(v1::NORMAL_DAMPING_CRITICAL_RATIO);
  law->set_damping_ratio(0.3);
  scene.mutable_effects(0)->mutable_contacts()->set_density_kg_m3(2650);
  scene.mutable_effects(0)->mutable_contacts()->set_dt_safety(0.2);
  auto* lattice = scene.mutable_packing()->mutable_lattice();
  lattice->set_columns(1000);
  lattice->set_rows(1000);
  auto fits = SceneFromProto(scene);
  ASSERT_TRUE(fits.ok()) << fits.status().ToString();
  EXPECT_LT(EstimateStateSize(*fits).total_bytes, kMaxSerializedStateBytes);

  lattice->set_columns(4000);
  lattice->set_rows(3000);
  auto spec = SceneFromProto(scene);
  ASSERT_FALSE(spec.ok());
  EXPECT_EQ(spec.status().code(), core::StatusCode::kInvalidArgument);
  const std::string message = spec.status().message();
  EXPECT_EQ(message.rfind("scene.packing: a checkpoint of this scene's state would take up to ", 0),
            0u)
      << message;
  EXPECT_NE(message.find("12000000 particles x "), std::string::npos) << message;
  EXPECT_NE(message.find("over the 2147483647 bytes protobuf can serialize"), std::string::npos)
      << message;
  EXPECT_NE(message.find("use at most "), std::string::npos) << message;

  // The same lattice on a frozen packing keeps only pressures: it fits.
  scene.clear_effects();
  EXPECT_TRUE(SceneFromProto(scene).ok());
}

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

INSTANTIATE_TEST_SUITE_P(CommonScenes, SceneCodecRejects,
                         ::testing::ValuesIn(testing::CommonBadScenes()),
                         [](const ::testing::TestParamInfo<BadScene>& param_info) {
                           return std::string(param_info.param.name);
                         });

INSTANTIATE_TEST_SUITE_P(
    RadialScenes, SceneCodecRejects,
    ::testing::Values(BadScene{"RadialWithAxis",
                               [](v1::Scene& s) {
                                 MakeRadial(s);
                                 s.mutable_boundary()->set_axis(v1::FLOW_AXIS_X);
                               },
                               "scene.boundary.axis:"},
                      BadScene{"RadialWithInletPressure",
                               [](v1::Scene& s) {
                                 MakeRadial(s);
                                 s.mutable_boundary()->set_inlet_pressure_pa(1);
                               },
                               "scene.boundary.inlet_pressure_pa:"},
                      BadScene{"RadialWithoutWellRadius",
                               [](v1::Scene& s) {
                                 MakeRadial(s);
                                 s.mutable_boundary()->mutable_radial()->clear_well_radius_m();
                               },
                               "scene.boundary.radial.well_radius_m:"},
                      BadScene{"RadialOuterInsideWell",
                               [](v1::Scene& s) {
                                 MakeRadial(s);
                                 s.mutable_boundary()->mutable_radial()->set_outer_radius_m(1e-3);
                               },
                               "scene.boundary.radial.outer_radius_m:"},
                      BadScene{"RadialInfiniteWellPressure",
                               [](v1::Scene& s) {
                                 MakeRadial(s);
                                 s.mutable_boundary()->mutable_radial()->set_well_pressure_pa(kInf);
                               },
                               "scene.boundary.radial.well_pressure_pa:"},
                      BadScene{"RadialNaNOuterPressure",
                               [](v1::Scene& s) {
                                 MakeRadial(s);
                                 s.mutable_boundary()->mutable_radial()->set_outer_pressure_pa(
                                     kNaN);
                               },
                               "scene.boundary.radial.outer_pressure_pa:"}),
    [](const ::testing::TestParamInfo<BadScene>& param_info) {
      return std::string(param_info.param.name);
    });

// A stage whose end condition is a duration, to which a test adds what it gets wrong.
v1::Stage* AddStage(v1::Scene& scene) {
  v1::Stage* stage = scene.add_stages();
  stage->set_name("s");
  stage->add_end()->set_duration_s(1);
  return stage;
}

// What the wire cannot say unambiguously: a Setting or EndCondition given with no arm set, and a
// breakthrough condition set to false.
INSTANTIATE_TEST_SUITE_P(
    StageScenes, SceneCodecRejects,
    ::testing::Values(
        BadScene{"StageSettingWithoutValueOrSchedule",
                 [](v1::Scene& s) { AddStage(s)->mutable_injection_rate_m2_s(); },
                 "scene.stages[0].injection_rate_m2_s: set one of value or schedule"},
        BadScene{"SecondStageOuterPressureWithoutValueOrSchedule",
                 [](v1::Scene& s) {
                   AddStage(s);
                   AddStage(s)->mutable_outer_pressure_pa();
                 },
                 "scene.stages[1].outer_pressure_pa: set one of value or schedule"},
        BadScene{"StageWallServoWithoutValueOrSchedule",
                 [](v1::Scene& s) {
                   AddStage(s);
                   v1::StageWall* wall = AddStage(s)->add_walls();
                   wall->set_wall(1);
                   wall->mutable_servo_stress_pa();
                 },
                 "scene.stages[1].walls[0].servo_stress_pa: set one of value or schedule"},
        BadScene{"StageWallDrainWithoutValueOrSchedule",
                 [](v1::Scene& s) {
                   v1::Stage* stage = AddStage(s);
                   stage->add_walls()->set_fixed(true);
                   stage->add_walls()->mutable_drain_pressure_pa();
                 },
                 "scene.stages[0].walls[1].drain_pressure_pa: set one of value or schedule"},
        BadScene{"EndConditionWithoutKind", [](v1::Scene& s) { AddStage(s)->add_end(); },
                 "scene.stages[0].end[1]: set one end condition (duration_s, steps, servo_held, "
                 "kinetic_energy_ratio, bonds_broken, breakthrough, well_pressure_past_peak)"},
        BadScene{"BreakthroughFalse",
                 [](v1::Scene& s) {
                   AddStage(s);
                   AddStage(s)->add_end()->set_breakthrough(false);
                 },
                 "scene.stages[1].end[1].breakthrough: must be true"}),
    [](const ::testing::TestParamInfo<BadScene>& param_info) {
      return std::string(param_info.param.name);
    });

}  // namespace
}  // namespace seep::service
