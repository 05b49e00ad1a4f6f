// The proto mapping of boundary regions (codec/region_codec.cc) and of a stage's region values
// (codec/stage_codec.cc): every shape and condition arrives in core with its numbers; a region
// without a shape or a condition is refused naming it (more refusals in bad_scenes.cc, which the
// real-server test submits too).
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <variant>

#include "codec/scene_codec.h"

namespace seep::service {
namespace {

v1::Scene SceneWithRegions() {
  v1::Scene scene;
  const bool ok = google::protobuf::TextFormat::ParseFromString(
      R"pb(
        name: "regions"
        packing { lattice { kind: LATTICE_KIND_SQUARE columns: 20 rows: 10 radius_m: 1e-3 } }
        fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2e9 }
        aperture { residual_aperture_m: 1e-5 }
        boundary {
          axis: FLOW_AXIS_X
          regions {
            name: "box"
            box { x0_m: 0 y0_m: 0 x1_m: 0.004 y1_m: 0.02 }
            pressure_pa: 2e5
          }
          regions {
            name: "well"
            circle { cx_m: 0.02 cy_m: 0.01 r_m: 0.003 }
            flux_m2_s: -1.5e-7
          }
          regions {
            name: "right"
            half_plane { px_m: 0.037 py_m: 0 nx: 1 ny: 0 }
            pressure_pa: 0
          }
          regions {
            name: "tri"
            polygon {
              x_m: [ 0.01, 0.014, 0.012 ]
              y_m: [ 0.001, 0.001, 0.004 ]
            }
            flux_m2_s: 2e-8
          }
        }
        solver { kind: SOLVER_KIND_IMPLICIT storage: STORAGE_VOLUME_PORE dt_factor: 10 }
        stages {
          name: "raise"
          regions {
            region: 0
            value { value: 3e5 }
          }
          regions {
            region: 1
            value {
              schedule {
                time_s: [ 0, 1e-3 ]
                value: [ -1.5e-7, 0 ]
              }
            }
          }
          regions { region: 2 }
          end { steps: 5 }
        }
      )pb",
      &scene);
  EXPECT_TRUE(ok);
  return scene;
}

TEST(RegionCodec, ConvertsEveryShapeConditionAndStageValue) {
  auto spec = SceneFromProto(SceneWithRegions());
  ASSERT_TRUE(spec.ok()) << spec.status().ToString();
  const auto& regions = spec->boundary.regions;
  ASSERT_EQ(regions.size(), 4u);
  EXPECT_EQ(regions[0].name, "box");
  const auto& box = std::get<core::BoxShape>(regions[0].shape);
  EXPECT_EQ(box.x1, 0.004);
  EXPECT_EQ(box.y1, 0.02);
  EXPECT_EQ(std::get<core::FixedPressure>(regions[0].condition).pressure_pa, 2e5);
  const auto& circle = std::get<core::CircleShape>(regions[1].shape);
  EXPECT_EQ(circle.cx, 0.02);
  EXPECT_EQ(circle.cy, 0.01);
  EXPECT_EQ(circle.r, 0.003);
  EXPECT_EQ(std::get<core::FixedFlux>(regions[1].condition).rate_m2_s, -1.5e-7);
  const auto& half = std::get<core::HalfPlaneShape>(regions[2].shape);
  EXPECT_EQ(half.px, 0.037);
  EXPECT_EQ(half.nx, 1.0);
  EXPECT_EQ(half.ny, 0.0);
  EXPECT_EQ(std::get<core::FixedPressure>(regions[2].condition).pressure_pa, 0.0);
  const auto& tri = std::get<core::PolygonShape>(regions[3].shape);
  EXPECT_EQ(tri.x, (std::vector<double>{0.01, 0.014, 0.012}));
  EXPECT_EQ(tri.y, (std::vector<double>{0.001, 0.001, 0.004}));
  EXPECT_EQ(std::get<core::FixedFlux>(regions[3].condition).rate_m2_s, 2e-8);

  const auto& stage = spec->stages.at(0).regions;
  ASSERT_EQ(stage.size(), 3u);
  EXPECT_EQ(stage[0].region, 0u);
  EXPECT_EQ(std::get<double>(*stage[0].value), 3e5);
  EXPECT_EQ(stage[1].region, 1u);
  const auto& schedule = std::get<core::ScheduleSpec>(*stage[1].value);
  EXPECT_EQ(schedule.time_s, (std::vector<double>{0.0, 1e-3}));
  EXPECT_EQ(schedule.value, (std::vector<double>{-1.5e-7, 0.0}));
  EXPECT_FALSE(stage[2].value.has_value());  // no value: the region keeps its pressure
}

TEST(RegionCodec, ARegionWithoutAShapeOrAConditionIsNamed) {
  v1::Scene scene = SceneWithRegions();
  scene.mutable_boundary()->mutable_regions(2)->clear_half_plane();
  EXPECT_EQ(SceneFromProto(scene).status().message(),
            "scene.boundary.regions[2]: set one shape (box, circle, half_plane, polygon)");
  scene = SceneWithRegions();
  scene.mutable_boundary()->mutable_regions(3)->clear_flux_m2_s();
  EXPECT_EQ(SceneFromProto(scene).status().message(),
            "scene.boundary.regions[3]: set one condition (pressure_pa, flux_m2_s)");
  scene = SceneWithRegions();
  scene.mutable_stages(0)->mutable_regions(0)->mutable_value()->clear_value();
  EXPECT_EQ(SceneFromProto(scene).status().code(), core::StatusCode::kInvalidArgument);
  EXPECT_EQ(SceneFromProto(scene).status().message().rfind(
                "scene.stages[0].regions[0].value: set one of value or schedule", 0),
            0u)
      << SceneFromProto(scene).status().message();
}

}  // namespace
}  // namespace seep::service
