// A JobStore on a fresh database in a scratch folder, and a queued job to insert: what the store
// tests share.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "store/job_store.h"

namespace seep::service {

class JobStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("seep-store-test-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "seep.db").string();
    auto store = JobStore::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
  }
  void TearDown() override {
    store_.reset();
    std::filesystem::remove_all(dir_);
  }

  static JobRecord NewJob(const std::string& id, std::optional<std::string> request_id = {}) {
    JobRecord job;
    job.id = id;
    job.name = "name-" + id;
    job.request_id = std::move(request_id);
    job.scene = std::string(
        "\x0a\x03"
        "abc",
        5);
    job.build_id = "test";
    job.created_at_ms = 1000;
    return job;
  }

  std::filesystem::path dir_;
  std::string path_;
  std::unique_ptr<JobStore> store_;
};

}  // namespace seep::service
