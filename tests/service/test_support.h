// What the in-process service tests share: a scratch folder per test and the example scenes.
#pragma once

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "seep/v1/scene.pb.h"

namespace seep::testing {

// <temp>/seep-<prefix>-<pid>-<test name>, created empty.
inline std::filesystem::path FreshTestDir(const std::string& prefix) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("seep-" + prefix + "-" + std::to_string(::getpid()) + "-" +
                    ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// A text-format scene file, parsed (the test fails when it does not parse).
inline v1::Scene SceneFile(const std::string& path) {
  v1::Scene scene;
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text.str(), &scene)) << path;
  return scene;
}

// An example scene of the repository (examples/<file>).
inline v1::Scene ExampleScene(const std::string& file) {
  return SceneFile(std::string(SEEP_EXAMPLES_DIR) + "/" + file);
}

// A scene of the service tests' own (tests/service/data/<file>).
inline v1::Scene TestDataScene(const std::string& file) {
  return SceneFile(std::string(SEEP_SERVICE_TEST_DATA_DIR) + "/" + file);
}

}  // namespace seep::testing
