// End to end through the real binaries: seepd on a free loopback port with its own data folder,
// driven by the seep CLI.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>

#include "process.h"
#include "seepd_fixture.h"

namespace seep::testing {
namespace {

// The shared fixture (seepd_fixture.h) under this suite's name.
class SeepdEndToEnd : public SeepdFixture {};

TEST_F(SeepdEndToEnd, SubmitWatchShowStoresTheLatticePermeability) {
  const std::string scene = std::string(SEEP_EXAMPLES_DIR) + "/darcy_square_lattice.textproto";
  const CommandResult submit = Seep({"submit", scene});
  ASSERT_EQ(submit.exit_code, 0) << submit.output;
  const std::string id = JobIdFrom(submit.output);
  ASSERT_FALSE(id.empty()) << submit.output;

  const CommandResult watch = Seep({"watch", id});
  ASSERT_EQ(watch.exit_code, 0) << watch.output;
  EXPECT_NE(watch.output.find("SUCCEEDED"), std::string::npos) << watch.output;

  const CommandResult show = Seep({"--json", "show", id});
  ASSERT_EQ(show.exit_code, 0) << show.output;
  const auto job = nlohmann::json::parse(show.output);
  EXPECT_EQ(job["id"], id);
  EXPECT_EQ(job["state"], "JOB_STATE_SUCCEEDED");
  // The example is a 60 x 40 square lattice, R = 1 mm, a0 = 10 um: k = a0^3 / (24 R) exactly.
  const double a0 = 1e-5;
  const double radius = 1e-3;
  const double exact = a0 * a0 * a0 / (24.0 * radius);
  const double k = job["result"]["metrics"]["permeability_m2"].get<double>();
  EXPECT_NEAR(k, exact, 1e-8 * exact);
  // Darcy: Q = k H dP / (mu L) with the sample's H = 39 * 2R and L = 60 * 2R.
  const double q = job["result"]["metrics"]["inflow_m2_per_s"].get<double>();
  EXPECT_NEAR(q, exact * (39 * 2 * radius) * 1e5 / (1e-3 * 60 * 2 * radius), 1e-8 * q);
  EXPECT_EQ(job["result"]["metrics"]["domain_count"].get<double>(), 59.0 * 39.0);
}

TEST_F(SeepdEndToEnd, HealthIsServingAndReflectionListsTheService) {
  const CommandResult health = Seep({"health"});
  ASSERT_EQ(health.exit_code, 0) << health.output;
  EXPECT_NE(health.output.find("status   SERVING"), std::string::npos) << health.output;
  EXPECT_NE(health.output.find("service  seep.v1.SeepService"), std::string::npos) << health.output;
  EXPECT_NE(health.output.find("service  grpc.health.v1.Health"), std::string::npos)
      << health.output;
}

TEST_F(SeepdEndToEnd, SameRequestIdGivesOneJob) {
  const std::string scene = std::string(SEEP_EXAMPLES_DIR) + "/darcy_square_lattice.textproto";
  const CommandResult first = Seep({"submit", scene, "--request-id", "same-key"});
  const CommandResult second = Seep({"submit", scene, "--request-id", "same-key"});
  ASSERT_EQ(first.exit_code, 0) << first.output;
  ASSERT_EQ(second.exit_code, 0) << second.output;
  EXPECT_EQ(JobIdFrom(first.output), JobIdFrom(second.output));
  EXPECT_NE(second.output.find("already submitted"), std::string::npos) << second.output;
  const CommandResult list = Seep({"--json", "list"});
  ASSERT_EQ(list.exit_code, 0) << list.output;
  EXPECT_EQ(nlohmann::json::parse(list.output)["jobs"].size(), 1u);
}

TEST_F(SeepdEndToEnd, BadInputGetsClearErrorsAndExitCodes) {
  // A scene file that does not parse: file, line and column, exit code 3 (INVALID_ARGUMENT).
  const std::string broken = Write("broken.textproto", "name: \"x\"\npacking { lattice {\n");
  const CommandResult parse = Seep({"submit", broken});
  EXPECT_EQ(parse.exit_code, 3) << parse.output;
  EXPECT_NE(parse.output.find("broken.textproto:3:"), std::string::npos) << parse.output;

  // A scene the server rejects: the field path comes back, exit code 3, nothing is stored.
  const std::string bad = Write("bad.textproto", R"pb(
    packing { lattice { kind: LATTICE_KIND_SQUARE columns: 4 rows: 4 radius_m: 1e-3 } }
    fluid { viscosity_pa_s: -1 bulk_modulus_pa: 2e9 }
    aperture { residual_aperture_m: 1e-5 }
    boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1 }
    solver { kind: SOLVER_KIND_STEADY }
  )pb");
  const CommandResult rejected = Seep({"submit", bad});
  EXPECT_EQ(rejected.exit_code, 3) << rejected.output;
  EXPECT_NE(rejected.output.find("scene.fluid.viscosity_pa_s"), std::string::npos)
      << rejected.output;
  const CommandResult list = Seep({"--json", "list"});
  EXPECT_TRUE(nlohmann::json::parse(list.output)["jobs"].empty()) << list.output;

  // An unknown job: NOT_FOUND, exit code 5.
  const CommandResult missing = Seep({"show", "j-0000000000000000"});
  EXPECT_EQ(missing.exit_code, 5) << missing.output;
  EXPECT_NE(missing.output.find("not found"), std::string::npos) << missing.output;
}

TEST_F(SeepdEndToEnd, UnreachableServerExitsWith14AndSigtermStopsCleanly) {
  EXPECT_EQ(server_.Stop(SIGTERM), 0);
  const CommandResult down = Seep({"--timeout", "2", "list"});
  EXPECT_EQ(down.exit_code, 14) << down.output;
  EXPECT_NE(down.output.find("unreachable"), std::string::npos) << down.output;
}

// seepd blocks SIGINT/SIGTERM in its own threads and takes them in its shutdown thread. Before,
// only library threads started before main (OpenBLAS's pool) had them open, so where there were
// none (one CPU, taskset -c 0, OPENBLAS_NUM_THREADS=1) a SIGTERM stayed pending for good and
// seepd only died to SIGKILL. The environment variable makes OpenBLAS start no pool here too.
TEST(SeepdSignals, SigtermStopsSeepdWhenNoLibraryThreadTakesSignals) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("seep-e2e-signals-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string port_file = (dir / "port").string();
  const std::string log = (dir / "seepd.out").string();
  ChildProcess server(
      {"/usr/bin/env", "OPENBLAS_NUM_THREADS=1", SEEPD_PATH, "--listen", "127.0.0.1:0",
       "--data-dir", (dir / "data").string(), "--port-file", port_file},
      log);
  ASSERT_GT(WaitForPortFile(port_file, std::chrono::seconds(30)), 0) << "see " << log;
  // 0 is a clean exit; 137 would be the SIGKILL that Stop sends after its timeout.
  EXPECT_EQ(server.Stop(SIGTERM, std::chrono::seconds(15)), 0) << "see " << log;
  const std::string text = ReadFile(log);
  EXPECT_NE(text.find("signal 15 received: shutting down"), std::string::npos) << text;
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace seep::testing
