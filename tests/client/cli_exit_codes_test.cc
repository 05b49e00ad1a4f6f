// The exit codes scripts rely on (seep --help lists them), through the real binary: 5 for a
// missing job, 14 for an unreachable server, 3 for a bad scene file with the file, line and field
// in the message, 64 for a wrong command line.
#include "seepd_fixture.h"

namespace seep::testing {
namespace {

using CliExitCodes = SeepdFixture;

TEST_F(CliExitCodes, MissingJobIs5ForEveryJobCommand) {
  const std::string missing = "j-0000000000000000";
  for (const char* command : {"show", "watch", "result", "cancel", "resume", "delete", "events"}) {
    SCOPED_TRACE(command);
    const CommandResult run = Seep({command, missing});
    EXPECT_EQ(run.exit_code, 5) << run.output;
    EXPECT_NE(run.output.find("not found"), std::string::npos) << run.output;
  }
  EXPECT_EQ(Seep({"--json", "show", missing}).exit_code, 5);
}

TEST_F(CliExitCodes, UnreachableServerIs14ForEveryCommand) {
  ASSERT_EQ(server_.Stop(SIGTERM), 0);  // nothing listens on the port any more
  const std::string scene = Example("darcy_square_lattice.textproto");
  const std::vector<std::vector<std::string>> commands = {
      {"list"},          {"show", "j-1"},   {"watch", "j-1"},  {"result", "j-1"},
      {"cancel", "j-1"}, {"resume", "j-1"}, {"submit", scene}, {"health"},
      {"calibrations"},  {"delete", "j-1"}, {"events", "j-1"}};
  for (auto args : commands) {
    SCOPED_TRACE(args[0]);
    args.insert(args.begin(), {"--timeout", "2"});
    const CommandResult run = Seep(args);
    EXPECT_EQ(run.exit_code, 14) << run.output;
    if (args[2] != "watch") {  // a stream has no deadline; its error names the failed call only
      EXPECT_NE(run.output.find("server " + address_ + " unreachable"), std::string::npos)
          << run.output;
    }
  }
}

TEST_F(CliExitCodes, TextSceneThatDoesNotParseIs3WithFileLineAndColumn) {
  const std::string path = Write("typo.textproto",
                                 "name: \"typo\"\n"
                                 "fluid {\n"
                                 "  viscosity: 1e-3\n"
                                 "}\n");
  const CommandResult run = Seep({"submit", path});
  EXPECT_EQ(run.exit_code, 3) << run.output;
  // Line 3, column 12: protobuf reports the position just after the unknown name.
  EXPECT_EQ(run.output.rfind(path + ":3:12: ", 0), 0u) << run.output;
  EXPECT_NE(run.output.find("no field named \"viscosity\""), std::string::npos) << run.output;
}

TEST_F(CliExitCodes, JsonSceneThatDoesNotParseIs3WithFileLineAndColumn) {
  const std::string path = Write("typo.json",
                                 "{\n"
                                 "  \"name\": \"typo\",\n"
                                 "  \"fluid\": { \"viscosity_pa_s\" 1e-3 }\n"
                                 "}\n");
  const CommandResult run = Seep({"submit", path});
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_EQ(run.output, path + ":3:31: Expected : between key:value pair.\n");

  const std::string unknown = Write("unknown.json", "{\n  \"name\": \"x\",\n  \"colour\": 1\n}\n");
  const CommandResult field = Seep({"submit", unknown});
  EXPECT_EQ(field.exit_code, 3) << field.output;
  EXPECT_EQ(field.output, unknown + ":3: scene.colour: no such field\n");
}

TEST_F(CliExitCodes, FieldTheServerRejectsIs3WithTheLineOfThatField) {
  const std::string text = Write("bad.textproto",
                                 "# a rejected viscosity\n"
                                 "name: \"bad\"\n"
                                 "packing {\n"
                                 "  lattice { kind: LATTICE_KIND_SQUARE columns: 4 rows: 4 "
                                 "radius_m: 1e-3 }\n"
                                 "}\n"
                                 "fluid {\n"
                                 "  bulk_modulus_pa: 2e9\n"
                                 "  viscosity_pa_s: -1\n"
                                 "}\n"
                                 "aperture { residual_aperture_m: 1e-5 }\n"
                                 "boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1 }\n"
                                 "solver { kind: SOLVER_KIND_STEADY }\n");
  const CommandResult run = Seep({"submit", text});
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_EQ(run.output.rfind(text + ":8: scene.fluid.viscosity_pa_s: ", 0), 0u) << run.output;

  const std::string json_scene = Write("bad.json", R"({
  "name": "bad",
  "packing": { "lattice": { "kind": "LATTICE_KIND_SQUARE", "columns": 4, "rows": 4,
                            "radiusM": 1e-3 } },
  "fluid": { "viscosityPaS": 1e-3, "bulkModulusPa": 2e9 },
  "aperture": { "residualApertureM": -1e-5 },
  "boundary": { "axis": "FLOW_AXIS_X", "inletPressurePa": 1 },
  "solver": { "kind": "SOLVER_KIND_STEADY" }
}
)");
  const CommandResult json_run = Seep({"submit", json_scene});
  EXPECT_EQ(json_run.exit_code, 3) << json_run.output;
  EXPECT_EQ(json_run.output.rfind(json_scene + ":6: scene.aperture.residual_aperture_m: ", 0), 0u)
      << json_run.output;
  // Nothing was stored.
  EXPECT_EQ(Json({"list"}).value("jobs", nlohmann::json::array()).size(), 0u);
}

TEST_F(CliExitCodes, MissingSceneFileIs3) {
  const std::string path = (dir_ / "absent.textproto").string();
  const CommandResult run = Seep({"submit", path});
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_EQ(run.output, path + ": cannot open the scene file\n");
}

TEST_F(CliExitCodes, WrongCommandLineIs64AndHelpListsTheExitCodes) {
  EXPECT_EQ(Seep({"frobnicate"}).exit_code, 64);
  EXPECT_EQ(Seep({"show"}).exit_code, 64);  // the job id is missing
  EXPECT_EQ(Seep({"list", "--limit", "0"}).exit_code, 64);
  // Step 0 is no checkpoint's: refused, not read as "the newest" (which exported another state).
  for (const char* command : {"export", "plot"}) {
    std::vector<std::string> args = {command, "j-1", "--step", "0"};
    if (std::string(command) == "export") args.insert(args.end(), {"--out", dir_.string()});
    const CommandResult run = Seep(args);
    EXPECT_EQ(run.exit_code, 64) << command << ": " << run.output;
    EXPECT_NE(run.output.find("--step"), std::string::npos) << run.output;
  }
  const CommandResult help = Seep({"--help"});
  EXPECT_EQ(help.exit_code, 0) << help.output;
  for (const char* line : {"Exit codes:", "  5   no such job", "  14  server unreachable",
                           "  20  the watched job FAILED", "  64  wrong command line"}) {
    EXPECT_NE(help.output.find(line), std::string::npos) << line << "\n" << help.output;
  }
}

}  // namespace
}  // namespace seep::testing
