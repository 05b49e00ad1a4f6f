// Scene files point their errors at the file, line and field: parse errors in text format and
// JSON, and the field paths the server names when it rejects a value.
#include "scene_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "seep/v1/calibration.pb.h"

namespace seep::client {
namespace {

class SceneFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("seep-scene-file-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  std::filesystem::path dir_;
};

// Line numbers below count from the first line of these strings (line 1 = `name:`).
constexpr const char* kText = R"(name: "x"
packing {
  lattice { kind: LATTICE_KIND_SQUARE columns: 4 rows: 4 radius_m: 1e-3 }
}
fluid {
  bulk_modulus_pa: 2e9
  viscosity_pa_s: -1
}
boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1 }
solver { kind: SOLVER_KIND_STEADY }
)";

TEST_F(SceneFileTest, TextFieldPathsMapToTheirLines) {
  MessageFile file;
  v1::Scene scene;
  const std::string path = Write("scene.textproto", kText);
  ASSERT_EQ(file.Load(path, &scene, "scene"), "");
  EXPECT_EQ(file.LineOf("fluid.viscosity_pa_s"), 7);
  EXPECT_EQ(file.LineOf("packing.lattice.radius_m"), 3);
  EXPECT_EQ(file.LineOf("boundary.inlet_pressure_pa"), 9);
  // Absent fields point at the nearest block that is written; nothing written: 0.
  EXPECT_EQ(file.LineOf("aperture.residual_aperture_m"), 0);
  EXPECT_EQ(file.LineOf("solver.end_time_s"), 10);
  EXPECT_EQ(
      file.PointAt("scene.fluid.viscosity_pa_s: must be a finite number > 0 (got -1)", "scene"),
      path + ":7: scene.fluid.viscosity_pa_s: must be a finite number > 0 (got -1)");
  EXPECT_EQ(file.PointAt("scene: is required", "scene"), path + ": scene: is required");
}

TEST_F(SceneFileTest, RepeatedFieldsMapToTheLineOfTheirValue) {
  MessageFile file;
  v1::Calibration calibration;
  const std::string path = Write("c.textproto",
                                 "name: \"c\"\n"
                                 "target_permeabilities_m2: 1e-13\n"
                                 "target_permeabilities_m2: -2e-13\n"
                                 "tags: [\"a\", \"b\"]\n");
  ASSERT_EQ(file.Load(path, &calibration, "calibration"), "");
  EXPECT_EQ(file.LineOf("target_permeabilities_m2[1]"), 3);
  EXPECT_EQ(file.LineOf("tags[1]"), 4);
  EXPECT_EQ(file.PointAt("calibration.target_permeabilities_m2[1]: must be > 0", "calibration"),
            path + ":3: calibration.target_permeabilities_m2[1]: must be > 0");
}

TEST_F(SceneFileTest, TextParseErrorsNameFileLineAndColumn) {
  MessageFile file;
  v1::Scene scene;
  const std::string path = Write("bad.textproto", "name: \"x\"\nfluid {\n  viscosity: 1\n}\n");
  const std::string error = file.Load(path, &scene, "scene");
  // protobuf reports the column just after the unknown name (the colon).
  EXPECT_EQ(error.rfind(path + ":3:12: ", 0), 0u) << error;
  EXPECT_NE(error.find("viscosity"), std::string::npos) << error;
}

TEST_F(SceneFileTest, JsonFieldPathsMapToTheirLinesInEitherSpelling) {
  MessageFile file;
  v1::Scene scene;
  const std::string path = Write("scene.json",
                                 "{\n"
                                 "  \"name\": \"x\",\n"
                                 "  \"fluid\": {\n"
                                 "    \"bulkModulusPa\": 2e9,\n"
                                 "    \"viscosityPaS\": -1\n"
                                 "  },\n"
                                 "  \"solver\": { \"kind\": \"SOLVER_KIND_STEADY\" }\n"
                                 "}\n");
  ASSERT_EQ(file.Load(path, &scene, "scene"), "");
  EXPECT_EQ(file.LineOf("fluid.viscosity_pa_s"), 5);
  EXPECT_EQ(file.LineOf("fluid.bulk_modulus_pa"), 4);
  EXPECT_EQ(file.LineOf("solver.end_time_s"), 7);
  EXPECT_EQ(file.PointAt("scene.fluid.viscosity_pa_s: must be > 0", "scene"),
            path + ":5: scene.fluid.viscosity_pa_s: must be > 0");
}

TEST_F(SceneFileTest, JsonSyntaxErrorsNameFileLineAndColumn) {
  MessageFile file;
  v1::Scene scene;
  // The colon after "bulk_modulus_pa" is missing: line 4, column 23 is where the parser stops.
  const std::string path = Write("bad.json",
                                 "{\n"
                                 "  \"fluid\": {\n"
                                 "    \"viscosity_pa_s\": 1,\n"
                                 "    \"bulk_modulus_pa\" 2\n"
                                 "  }\n"
                                 "}\n");
  const std::string error = file.Load(path, &scene, "scene");
  EXPECT_EQ(error, path + ":4:23: Expected : between key:value pair.") << error;
}

TEST_F(SceneFileTest, JsonBadValuesAndUnknownFieldsNameTheFieldAndItsLine) {
  v1::Scene scene;
  MessageFile bad_value;
  const std::string value_path = Write("value.json",
                                       "{\n"
                                       "  \"fluid\": {\n"
                                       "    \"viscosity_pa_s\": \"thick\"\n"
                                       "  }\n"
                                       "}\n");
  EXPECT_EQ(
      bad_value.Load(value_path, &scene, "scene"),
      value_path + ":3: scene.fluid.viscosity_pa_s: invalid value \"thick\" for type TYPE_DOUBLE");

  MessageFile unknown;
  const std::string unknown_path = Write("unknown.json",
                                         "{\n"
                                         "  \"fluid\": {\n"
                                         "    \"viscosity_pa_s\": 1,\n"
                                         "    \"density\": 1000\n"
                                         "  }\n"
                                         "}\n");
  EXPECT_EQ(unknown.Load(unknown_path, &scene, "scene"),
            unknown_path + ":4: scene.fluid.density: no such field");
}

TEST_F(SceneFileTest, MissingFileSaysSo) {
  MessageFile file;
  v1::Scene scene;
  const std::string path = (dir_ / "absent.textproto").string();
  EXPECT_EQ(file.Load(path, &scene, "scene"), path + ": cannot open the scene file");
}

}  // namespace
}  // namespace seep::client
