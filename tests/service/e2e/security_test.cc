// Security defaults through the real binaries: the bearer token (seepd --token-file, seep --token,
// SEEP_TOKEN), TLS with a self-signed certificate made by the openssl CLI at test time, and the
// request and scene size limits.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "process.h"

namespace seep::testing {
namespace {

constexpr char kToken[] = "s3cret-Token_0123456789";
constexpr char kOpenssl[] = "/usr/bin/openssl";  // RunCommand does not search PATH

class SeepdSecurity : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("seep-sec-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    ::unsetenv("SEEP_TOKEN");  // each test sets it where it means to
    scene_ = std::string(SEEP_EXAMPLES_DIR) + "/darcy_square_lattice.textproto";
  }
  void TearDown() override {
    if (server_.running()) server_.Stop(SIGTERM);
    if (!HasFailure()) std::filesystem::remove_all(dir_);
  }

  // Starts seepd on a free loopback port with these extra flags; false if it did not come up.
  bool StartSeepd(const std::vector<std::string>& extra) {
    const std::string port_file = (dir_ / "port").string();
    std::vector<std::string> argv = {
        SEEPD_PATH,    "--listen", "127.0.0.1:0", "--data-dir", (dir_ / "data").string(),
        "--port-file", port_file};
    argv.insert(argv.end(), extra.begin(), extra.end());
    server_ = ChildProcess(argv, (dir_ / "seepd.out").string());
    const int port = WaitForPortFile(port_file, std::chrono::seconds(30));
    if (port <= 0) return false;
    address_ = "127.0.0.1:" + std::to_string(port);
    return true;
  }

  // seepd run to completion: for start-up refusals.
  CommandResult RunSeepd(const std::vector<std::string>& extra) {
    std::vector<std::string> argv = {SEEPD_PATH, "--listen", "127.0.0.1:0", "--data-dir",
                                     (dir_ / "data").string()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return RunCommand(argv);
  }

  CommandResult Seep(std::vector<std::string> args) {
    args.insert(args.begin(), {SEEP_CLI_PATH, "--server", address_});
    return RunCommand(args);
  }

  std::string WriteFile(const std::string& name, const std::string& text,
                        std::filesystem::perms perms = std::filesystem::perms::owner_read |
                                                       std::filesystem::perms::owner_write) {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    std::filesystem::permissions(path, perms);
    return path.string();
  }

  // A self-signed certificate for localhost and 127.0.0.1, made with the openssl CLI.
  void MakeCertificate() {
    cert_ = (dir_ / "cert.pem").string();
    key_ = (dir_ / "key.pem").string();
    const CommandResult made =
        RunCommand({kOpenssl, "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "1",
                    "-subj", "/CN=localhost", "-addext",
                    "subjectAltName=DNS:localhost,IP:127.0.0.1", "-keyout", key_, "-out", cert_});
    ASSERT_EQ(made.exit_code, 0) << made.output;
  }

  // A scene whose packing is an explicit list of n particles: about 24 bytes each on the wire
  // (three packed doubles), so its size is set by n.
  std::string WriteParticleScene(const std::string& name, int n) {
    std::ostringstream x, y, r;
    for (int i = 0; i < n; ++i) {
      const char* sep = i == 0 ? "" : ",";
      x << sep << 2e-3 * (i % 100) + 1e-3;
      y << sep << 2e-3 * (i / 100) + 1e-3;
      r << sep << 1e-3;
    }
    return WriteFile(name, "name: \"big\"\npacking { particles { x_m: [" + x.str() + "] y_m: [" +
                               y.str() + "] radius_m: [" + r.str() + "] } }\n" +
                               R"pb(fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
                                    aperture { residual_aperture_m: 1e-5 }
                                    boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
                                    solver { kind: SOLVER_KIND_STEADY })pb");
  }

  std::size_t JobCount(const std::vector<std::string>& auth) {
    std::vector<std::string> args = auth;
    args.insert(args.end(), {"--json", "list"});
    const CommandResult list = Seep(args);
    EXPECT_EQ(list.exit_code, 0) << list.output;
    return nlohmann::json::parse(list.output)["jobs"].size();
  }

  std::filesystem::path dir_;
  ChildProcess server_;
  std::string address_;
  std::string scene_;
  std::string cert_;
  std::string key_;
};

// gRPC's UNAUTHENTICATED, which the CLI returns as its exit code.
constexpr int kUnauthenticated = 16;

TEST_F(SeepdSecurity, TokenIsRequiredForJobCallsButNotForHealth) {
  const std::string token_file = WriteFile("token", std::string(kToken) + "\n");
  ASSERT_TRUE(StartSeepd({"--token-file", token_file})) << "see " << (dir_ / "seepd.out");

  const CommandResult missing = Seep({"submit", scene_});
  EXPECT_EQ(missing.exit_code, kUnauthenticated) << missing.output;
  EXPECT_NE(missing.output.find("missing 'authorization: Bearer <token>'"), std::string::npos)
      << missing.output;

  const CommandResult wrong = Seep({"--token", "not-the-token", "list"});
  EXPECT_EQ(wrong.exit_code, kUnauthenticated) << wrong.output;
  EXPECT_NE(wrong.output.find("bearer token is not the one"), std::string::npos) << wrong.output;
  // A prefix of the right token is still wrong (the comparison covers the length).
  const CommandResult prefix = Seep({"--token", std::string(kToken).substr(0, 10), "list"});
  EXPECT_EQ(prefix.exit_code, kUnauthenticated) << prefix.output;

  // Probes need no secret.
  const CommandResult health = Seep({"health"});
  EXPECT_EQ(health.exit_code, 0) << health.output;
  EXPECT_NE(health.output.find("status   SERVING"), std::string::npos) << health.output;

  // Nothing was stored by the refused submit.
  EXPECT_EQ(JobCount({"--token", kToken}), 0u);

  const CommandResult submit = Seep({"--token", kToken, "submit", scene_, "--watch"});
  ASSERT_EQ(submit.exit_code, 0) << submit.output;
  EXPECT_NE(submit.output.find("SUCCEEDED"), std::string::npos) << submit.output;

  // The same token from --token-file and from SEEP_TOKEN.
  EXPECT_EQ(JobCount({"--token-file", token_file}), 1u);
  ::setenv("SEEP_TOKEN", kToken, 1);
  const std::size_t from_env = JobCount({});
  ::unsetenv("SEEP_TOKEN");
  EXPECT_EQ(from_env, 1u);
}

TEST_F(SeepdSecurity, TokenFromTheEnvironmentProtectsTheServer) {
  ::setenv("SEEP_TOKEN", kToken, 1);  // read by seepd at start-up
  const bool started = StartSeepd({});
  ::unsetenv("SEEP_TOKEN");
  ASSERT_TRUE(started) << "see " << (dir_ / "seepd.out");
  EXPECT_EQ(Seep({"list"}).exit_code, kUnauthenticated);
  EXPECT_EQ(JobCount({"--token", kToken}), 0u);
}

TEST_F(SeepdSecurity, UnusableTokenFilesAndHalfTlsConfigsStopStartUp) {
  const CommandResult absent = RunSeepd({"--token-file", (dir_ / "nope").string()});
  EXPECT_NE(absent.exit_code, 0);
  EXPECT_NE(absent.output.find("does not exist"), std::string::npos) << absent.output;

  const CommandResult empty = RunSeepd({"--token-file", WriteFile("empty", "\n")});
  EXPECT_NE(empty.exit_code, 0);
  EXPECT_NE(empty.output.find("is empty"), std::string::npos) << empty.output;

  using std::filesystem::perms;
  const CommandResult shared = RunSeepd(
      {"--token-file",
       WriteFile("shared", kToken, perms::owner_read | perms::group_read | perms::others_read)});
  EXPECT_NE(shared.exit_code, 0);
  EXPECT_NE(shared.output.find("chmod 600"), std::string::npos) << shared.output;

  const CommandResult half = RunSeepd({"--tls-cert", WriteFile("c.pem", "x")});
  EXPECT_NE(half.exit_code, 0);
  EXPECT_NE(half.output.find("--tls-key"), std::string::npos) << half.output;
}

TEST_F(SeepdSecurity, TlsClientTalksToTlsServerAndPlaintextClientFails) {
  MakeCertificate();
  if (HasFatalFailure()) return;
  const std::string token_file = WriteFile("token", kToken);
  ASSERT_TRUE(StartSeepd({"--tls-cert", cert_, "--tls-key", key_, "--token-file", token_file}))
      << "see " << (dir_ / "seepd.out");

  const CommandResult health = Seep({"--tls-ca", cert_, "health"});
  EXPECT_EQ(health.exit_code, 0) << health.output;
  const CommandResult submit =
      Seep({"--tls-ca", cert_, "--token", kToken, "submit", scene_, "--watch"});
  ASSERT_EQ(submit.exit_code, 0) << submit.output;
  EXPECT_NE(submit.output.find("SUCCEEDED"), std::string::npos) << submit.output;
  // Over TLS the token is still required.
  EXPECT_EQ(Seep({"--tls-ca", cert_, "list"}).exit_code, kUnauthenticated);

  // A plaintext client cannot talk to a TLS server (no handshake: UNAVAILABLE = 14).
  const CommandResult plain = Seep({"--timeout", "3", "--token", kToken, "list"});
  EXPECT_EQ(plain.exit_code, 14) << plain.output;
  // Nor can a TLS client that does not trust the self-signed certificate.
  const CommandResult untrusted = Seep({"--timeout", "3", "--tls", "health"});
  EXPECT_EQ(untrusted.exit_code, 14) << untrusted.output;
}

TEST_F(SeepdSecurity, OversizedScenesAreRefusedAndNothingIsStored) {
  // Limits small enough for test files: scenes up to 100 kB, requests up to 1 MB.
  ASSERT_TRUE(StartSeepd({"--max-scene-bytes", "100000", "--max-message-bytes", "1000000"}))
      << "see " << (dir_ / "seepd.out");

  // 5000 particles, about 120 kB: over the scene limit, under the request limit.
  const CommandResult big = Seep({"submit", WriteParticleScene("big.textproto", 5000)});
  EXPECT_EQ(big.exit_code, 3) << big.output;  // INVALID_ARGUMENT
  EXPECT_NE(big.output.find("exceed the limit of 100000 (seepd --max-scene-bytes)"),
            std::string::npos)
      << big.output;

  // 50000 particles, about 1.2 MB: gRPC refuses the request itself.
  const CommandResult huge = Seep({"submit", WriteParticleScene("huge.textproto", 50000)});
  EXPECT_EQ(huge.exit_code, 8) << huge.output;  // RESOURCE_EXHAUSTED
  EXPECT_NE(huge.output.find("1000000"), std::string::npos) << huge.output;

  EXPECT_EQ(JobCount({}), 0u);
  // A scene under the limits still goes through.
  const CommandResult small = Seep({"submit", scene_});
  EXPECT_EQ(small.exit_code, 0) << small.output;
  EXPECT_EQ(JobCount({}), 1u);
}

}  // namespace
}  // namespace seep::testing
