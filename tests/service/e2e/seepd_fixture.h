// A real seepd on a free loopback port with its own data folder, and the real seep CLI run
// against it with stdout a pipe (not a terminal): what the CLI and service e2e tests share.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "file_text.h"
#include "process.h"

namespace seep::testing {

class SeepdFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("seep-client-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    const std::string port_file = (dir_ / "port").string();
    std::vector<std::string> command = {
        SEEPD_PATH,    "--listen", "127.0.0.1:0", "--data-dir", (dir_ / "data").string(),
        "--port-file", port_file};
    for (const std::string& flag : ExtraSeepdFlags()) command.push_back(flag);
    server_ = ChildProcess(command, (dir_ / "seepd.out").string());
    const int port = WaitForPortFile(port_file, std::chrono::seconds(30));
    ASSERT_GT(port, 0) << "seepd did not start; see " << (dir_ / "seepd.out");
    address_ = "127.0.0.1:" + std::to_string(port);
  }
  // Flags a suite adds to seepd's command line (workers, checkpoint cadence, ...).
  virtual std::vector<std::string> ExtraSeepdFlags() const { return {}; }

  void TearDown() override {
    if (server_.running()) server_.Stop(SIGTERM);
    if (!HasFailure()) std::filesystem::remove_all(dir_);
  }

  CommandResult Seep(std::vector<std::string> args) {
    args.insert(args.begin(), {SEEP_CLI_PATH, "--server", address_});
    return RunCommand(args);
  }

  // Runs a read command with --json and parses stdout (the test fails on an exit code or bad JSON).
  nlohmann::json Json(std::vector<std::string> args) {
    args.insert(args.begin(), "--json");
    const CommandResult run = Seep(args);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    const auto parsed = nlohmann::json::parse(run.output, nullptr, /*allow_exceptions=*/false);
    EXPECT_FALSE(parsed.is_discarded()) << "not JSON: " << run.output;
    return parsed;
  }

  std::string Write(const std::string& name, const std::string& text) {
    const auto path = dir_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  static std::string JobIdFrom(const std::string& submit_output) {
    std::smatch m;
    if (std::regex_search(submit_output, m, std::regex("job (j-[0-9a-f]+)"))) return m[1];
    return {};
  }

  static std::string Example(const std::string& name) {
    return std::string(SEEP_EXAMPLES_DIR) + "/" + name;
  }

  std::filesystem::path dir_;
  ChildProcess server_;
  std::string address_;
};

}  // namespace seep::testing
