// Runs that never get lost: the real seepd is killed with SIGKILL at random points while jobs
// run, restarted on the same data folder, and every job must finish with a final state
// bit-identical (same SHA-256) to the same scene run without interruption. Also: a truncated or
// corrupted newest checkpoint falls back to the previous one, SIGTERM checkpoints before it
// exits, and a cancelled job resumes from where it stopped.
#include <google/protobuf/text_format.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <thread>

#include "grpc_seepd_fixture.h"
#include "store/job_store.h"

namespace seep::testing {
namespace {

// Three transient scenes of a few seconds each: explicit on a square lattice, explicit on a
// seeded random packing, backward Euler on a hex lattice.
const char* const kScenes[] = {
    R"pb(
      name: "explicit-lattice"
      packing { lattice { kind: LATTICE_KIND_SQUARE columns: 80 rows: 50 radius_m: 1e-3 } }
      fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
      aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
      boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
      solver {
        kind: SOLVER_KIND_EXPLICIT
        storage: STORAGE_VOLUME_PORE
        dt_factor: 0.9
        end_time_s: SEEP_EXPLICIT_END
      }
    )pb",
    R"pb(
      name: "explicit-random"
      packing {
        random {
          seed: 5
          width_m: 0.04
          height_m: 0.02
          min_radius_m: 0.8e-3
          max_radius_m: 1.0e-3
          particle_count: 300
          target_porosity: 0.2
        }
        contact_gap_m: 2e-5
      }
      fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
      aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
      boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
      solver {
        kind: SOLVER_KIND_EXPLICIT
        storage: STORAGE_VOLUME_PORE
        dt_factor: 0.9
        end_time_s: SEEP_RANDOM_END
      }
    )pb",
    R"pb(
      name: "implicit-hex"
      packing { lattice { kind: LATTICE_KIND_HEX columns: 120 rows: 80 radius_m: 1e-3 } }
      fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
      aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
      boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
      solver {
        kind: SOLVER_KIND_IMPLICIT
        storage: STORAGE_VOLUME_PORE
        dt_factor: 5
        end_time_s: SEEP_IMPLICIT_END
      }
    )pb",
};

// The scene of `text` with its end-time placeholders (SEEP_*_END) filled in.
v1::Scene SceneWithEndTimes(std::string text) {
  text = std::regex_replace(text, std::regex("SEEP_EXPLICIT_END"), "4e-2");
  text = std::regex_replace(text, std::regex("SEEP_RANDOM_END"), "6e-2");
  text = std::regex_replace(text, std::regex("SEEP_IMPLICIT_END"), "1e-3");
  v1::Scene scene;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &scene)) << text;
  return scene;
}

class CrashRecovery : public GrpcSeepdTest {
 protected:
  CrashRecovery() : GrpcSeepdTest("e2e-crash") {}

  // Waits until a job has at least `n` checkpoint files and its newest file name sorts after
  // `newer_than`; returns them sorted by step (the names hold the zero-padded step).
  std::vector<std::filesystem::path> WaitForCheckpoints(const std::string& data,
                                                        const std::string& id, std::size_t n,
                                                        const std::string& newer_than = "") {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    for (;;) {
      std::vector<std::filesystem::path> files;
      std::error_code ec;
      for (const auto& e :
           std::filesystem::directory_iterator(dir_ / data / "checkpoints" / id, ec)) {
        if (e.path().extension() == ".bin") files.push_back(e.path());
      }
      std::sort(files.begin(), files.end());
      const bool newer = !files.empty() && files.back().filename().string() > newer_than;
      if ((files.size() >= n && newer) || std::chrono::steady_clock::now() > deadline) {
        return files;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  // The files of `files` that the data folder's store has a record of (seepd is stopped).
  std::vector<std::filesystem::path> RecordedCheckpoints(
      const std::string& data, const std::string& id,
      const std::vector<std::filesystem::path>& files) {
    auto store = service::JobStore::Open((dir_ / data / "seep.db").string());
    EXPECT_TRUE(store.ok()) << store.status().message();
    if (!store.ok()) return {};
    auto records = (*store)->ListCheckpoints(id);
    EXPECT_TRUE(records.ok()) << records.status().message();
    if (!records.ok()) return {};
    std::vector<std::filesystem::path> recorded;
    for (const auto& file : files) {
      for (const auto& record : *records) {
        if (std::filesystem::path(record.path).filename() == file.filename()) {
          recorded.push_back(file);
          break;
        }
      }
    }
    return recorded;
  }
};

// The hydraulic-fracturing example cut short after its breakdown: moving particles, bonds
// breaking, domains re-detected; its checkpoints carry the whole DEM state.
v1::Scene CoupledScene() {
  v1::Scene scene = SceneWithEndTimes(
      ReadFile(std::string(SEEP_EXAMPLES_DIR) + "/hydraulic_fracturing.textproto"));
  scene.set_name("coupled-hydrofrac");
  scene.mutable_solver()->set_end_time_s(0.026);
  return scene;
}

TEST_F(CrashRecovery, SigkillAtRandomPointsEndsBitIdenticalToAnUninterruptedRun) {
  std::vector<v1::Scene> scenes;
  for (const char* text : kScenes) scenes.push_back(SceneWithEndTimes(text));
  scenes.push_back(CoupledScene());
  const std::vector<std::string> expected = ReferenceHashes(scenes);
  ASSERT_FALSE(HasFailure());

  // Checkpoints on a short wall-time trigger, so they land at steps nobody chose. A slow build
  // (the sanitizers') may be killed again before a job's next checkpoint: interruptions without
  // progress are this test's doing, not a crash loop.
  const std::vector<std::string> flags = {
      "--workers", "2", "--checkpoint-interval-s", "0.15", "--max-interruptions", "1000"};
  Start("crash", flags);
  std::vector<std::string> ids;
  for (const auto& s : scenes) ids.push_back(Submit(s));

  const unsigned seed = 20261123;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> delay_ms(300, 1500);
  int kills = 0;
  for (int round = 0; round < 4; ++round) {
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
    stub_.reset();
    EXPECT_EQ(server_.Stop(SIGKILL), 128 + SIGKILL);
    ++kills;
    Start("crash", flags);
  }
  ExpectBitIdenticalToUninterrupted(
      ids, expected, "seed " + std::to_string(seed) + ", " + std::to_string(kills) + " kills");
  // At least one job really continued from a checkpoint (not only from the start).
  const std::string log = ReadFile(dir_ / "crash.out");
  EXPECT_NE(log.find("resumed from checkpoint"), std::string::npos) << log;
}

TEST_F(CrashRecovery, TruncatedThenCorruptedNewestCheckpointFallsBackToThePreviousOne) {
  const v1::Scene scene = SceneWithEndTimes(kScenes[1]);
  const std::string expected = ReferenceHashes({scene})[0];
  ASSERT_FALSE(HasFailure());

  const std::vector<std::string> flags = {"--checkpoint-interval-s", "0.1", "--checkpoints-kept",
                                          "5"};
  Start("damaged", flags);
  const std::string id = Submit(scene);
  std::string damaged_before;  // the file damaged in the previous round
  for (const std::string damage : {"truncate", "flip"}) {
    // The run is going (again) and has written checkpoints past the previous damage.
    const auto files = WaitForCheckpoints("damaged", id, 3, damaged_before);
    ASSERT_GE(files.size(), 3u);
    ASSERT_GT(files.back().filename().string(), damaged_before);
    ASSERT_EQ(Get(id).state(), v1::JOB_STATE_RUNNING) << "the scene ran out before the kill";
    stub_.reset();
    ASSERT_EQ(server_.Stop(SIGKILL), 128 + SIGKILL);
    // The newest file after the kill (one may have landed after the listing above) that the
    // store recorded: a kill between a file and its record leaves a file no restart reads.
    const auto after = RecordedCheckpoints("damaged", id, WaitForCheckpoints("damaged", id, 3));
    ASSERT_GE(after.size(), 2u);
    const std::filesystem::path newest = after.back();
    // The newest file before it that is not damaged already.
    std::filesystem::path previous;
    for (auto it = after.rbegin() + 1; it != after.rend() && previous.empty(); ++it) {
      if (it->filename().string() != damaged_before) previous = *it;
    }
    ASSERT_FALSE(previous.empty());
    std::string bytes = ReadFile(newest);
    if (damage == "truncate") {
      bytes.resize(bytes.size() / 2);
    } else {
      bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x5a);
    }
    std::ofstream(newest, std::ios::binary | std::ios::trunc) << bytes;
    damaged_before = newest.filename().string();
    Start("damaged", flags);
    // The restarted job names the damaged file it skips, then continues from the one before.
    const std::string skipped = newest.filename().string() + " (step";
    const std::string resumed = "resumed from checkpoint " + previous.filename().string();
    const auto logged = [&] {
      const std::string log = ReadFile(dir_ / "damaged.out");
      const std::size_t at = log.find(skipped);
      return at != std::string::npos && log.find(resumed, at) != std::string::npos;
    };
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!logged() && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const std::string log = ReadFile(dir_ / "damaged.out");
    EXPECT_TRUE(logged()) << damage << ": expected '" << skipped << "' then '" << resumed << "'\n"
                          << log;
    EXPECT_NE(log.find("DATA_LOSS"), std::string::npos) << log;
  }
  auto jobs = WaitAllTerminal({id}, std::chrono::seconds(300));
  ASSERT_EQ(jobs[id].state(), v1::JOB_STATE_SUCCEEDED) << jobs[id].DebugString();
  EXPECT_EQ(jobs[id].result().state_sha256(), expected);
}

TEST_F(CrashRecovery, SigtermCheckpointsAndACancelledJobResumesWhereItStopped) {
  // Ten times the shared lattice run (about 3 s here): the SIGTERM 400 ms in must find it
  // running even on a machine several times faster than this one.
  v1::Scene scene = SceneWithEndTimes(kScenes[0]);
  scene.mutable_solver()->set_end_time_s(10 * scene.solver().end_time_s());
  const std::string expected = ReferenceHashes({scene})[0];
  ASSERT_FALSE(HasFailure());

  // No periodic checkpoints: only the ones written on SIGTERM and on cancel.
  const std::vector<std::string> flags = {"--checkpoint-interval-s", "0"};
  Start("graceful", flags);
  const std::string id = Submit(scene);
  while (Get(id).progress().step() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);
  const std::string first = ReadFile(dir_ / "graceful.out");
  std::smatch stopped;
  ASSERT_TRUE(
      std::regex_search(first, stopped, std::regex("interrupted by shutdown .* at step (\\d+)")))
      << first;
  Start("graceful", flags);
  // The restarted run continues from the step the shutdown reached.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  const std::string resumed = "at step " + stopped[1].str() + " (t =";
  while (ReadFile(dir_ / "graceful.out").find(resumed) == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_NE(ReadFile(dir_ / "graceful.out").find(resumed), std::string::npos);

  // Cancel, then resume: the second attempt starts from the cancelled step, not from 0.
  {
    grpc::ClientContext ctx;
    v1::CancelJobRequest request;
    request.set_id(id);
    v1::CancelJobResponse response;
    const grpc::Status status = stub_->CancelJob(&ctx, request, &response);
    // FAILED_PRECONDITION only when the run already finished (handled below).
    ASSERT_TRUE(status.ok() || status.error_code() == grpc::StatusCode::FAILED_PRECONDITION)
        << status.error_message();
  }
  auto cancelled = WaitAllTerminal({id}, std::chrono::seconds(60));
  if (cancelled[id].state() == v1::JOB_STATE_CANCELLED) {
    const std::uint64_t at = cancelled[id].progress().step();
    grpc::ClientContext ctx;
    v1::ResumeJobRequest request;
    request.set_id(id);
    v1::ResumeJobResponse response;
    ASSERT_TRUE(stub_->ResumeJob(&ctx, request, &response).ok());
    auto done = WaitAllTerminal({id}, std::chrono::seconds(300));
    ASSERT_EQ(done[id].state(), v1::JOB_STATE_SUCCEEDED);
    EXPECT_EQ(done[id].attempt(), 2u);
    EXPECT_EQ(done[id].result().state_sha256(), expected);
    const std::string log = ReadFile(dir_ / "graceful.out");
    EXPECT_NE(log.find("resumed from checkpoint ckpt-"), std::string::npos);
    EXPECT_GT(at, 0u);
  } else {
    // The run finished before the cancel reached it; the hash must still match.
    ASSERT_EQ(cancelled[id].state(), v1::JOB_STATE_SUCCEEDED);
    EXPECT_EQ(cancelled[id].result().state_sha256(), expected);
  }
}

}  // namespace
}  // namespace seep::testing
