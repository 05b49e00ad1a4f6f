// The operations of a job service, through the real seepd and seep: labels, opaque page tokens,
// DeleteJob and `seep delete`, the event log and `seep events`, the retention policy, the
// checkpoint folder (private modes, the start-up sweep, a moved data folder), health while
// draining with the shutdown time limit and a second signal, and store errors without SQL.
#include <google/protobuf/util/time_util.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <thread>

#include "grpc/health/v1/health.grpc.pb.h"
#include "grpc_seepd_fixture.h"

namespace seep::testing {
namespace {

namespace fs = std::filesystem;

class ServiceOperations : public GrpcSeepdTest {
 protected:
  ServiceOperations() : GrpcSeepdTest("e2e-ops") {}

  void Start(const std::string& data, const std::vector<std::string>& extra) {
    GrpcSeepdTest::Start(data, extra);
    data_ = data;
    const std::string port = ReadFile(dir_ / (data + ".port"));
    address_ = "127.0.0.1:" + port.substr(0, port.find('\n'));
  }

  CommandResult Cli(std::vector<std::string> args) {
    args.insert(args.begin(), {SEEP_CLI_PATH, "--server", address_});
    return RunCommand(args);
  }
  nlohmann::json CliJson(std::vector<std::string> args) {
    args.insert(args.begin(), "--json");
    const CommandResult run = Cli(args);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    const auto parsed = nlohmann::json::parse(run.output, nullptr, /*allow_exceptions=*/false);
    EXPECT_FALSE(parsed.is_discarded()) << run.output;
    return parsed;
  }
  // The lattice scene as a text file for `seep submit`.
  std::string SceneFile(const std::string& name, double end_time_s) {
    std::string text;
    EXPECT_TRUE(google::protobuf::TextFormat::PrintToString(LatticeScene(name, end_time_s), &text));
    const std::string path = (dir_ / (name + ".textproto")).string();
    std::ofstream(path) << text;
    return path;
  }
  static std::string IdFrom(const CommandResult& run) {
    std::smatch m;
    return std::regex_search(run.output, m, std::regex("job (j-[0-9a-f]{16})")) ? m[1].str() : "";
  }

  v1::Job WaitRunningPast(const std::string& id, std::uint64_t step) {
    return WaitFor(id, [step](const v1::Job& j) {
      return j.state() == v1::JOB_STATE_RUNNING && j.progress().step() > step;
    });
  }
  std::string Log() const { return ReadFile(dir_ / data_ / "seepd.log"); }
  // Waits until the log holds `what` (true) or the timeout passes (false).
  bool WaitForLog(const std::string& what, std::chrono::seconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (Log().find(what) == std::string::npos) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return true;
  }
  fs::path CheckpointFolder(const std::string& id) const {
    return dir_ / data_ / "checkpoints" / id;
  }
  std::set<std::string> CheckpointFiles(const std::string& id) const {
    std::set<std::string> names;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(CheckpointFolder(id), ec)) {
      names.insert(e.path().filename().string());
    }
    return names;
  }
  // The bytes of the job's final state as its last CHECKPOINT event gives them (the store holds a
  // small one, so no file shows it); 0 when it has none.
  std::uint64_t FinalStateBytes(const std::string& id) {
    std::uint64_t bytes = 0;
    const nlohmann::json events = CliJson({"events", id});
    for (const auto& e : events["events"]) {
      std::smatch m;
      const std::string message = e["message"];
      if (e["kind"] == "CHECKPOINT" &&
          std::regex_search(message, m, std::regex(", ([0-9]+) bytes, attempt"))) {
        bytes = std::stoull(m[1].str());
      }
    }
    return bytes;
  }
  grpc::health::v1::HealthCheckResponse::ServingStatus Health() {
    auto health = grpc::health::v1::Health::NewStub(
        grpc::CreateChannel(address_, grpc::InsecureChannelCredentials()));
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(2));
    grpc::health::v1::HealthCheckRequest request;
    grpc::health::v1::HealthCheckResponse response;
    if (!health->Check(&ctx, request, &response).ok()) {
      return grpc::health::v1::HealthCheckResponse::UNKNOWN;
    }
    return response.status();
  }
  // Waits for seepd to end by itself; its exit status, or -1 after the timeout.
  int WaitForExit(std::chrono::seconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (const int status = server_.PollExit(); status >= 0) return status;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }

  std::string data_;
  std::string address_;
};

TEST_F(ServiceOperations, LabelsAreCheckedAtSubmitAndFilterTheList) {
  Start("data", {});
  const std::string scene = SceneFile("labelled", 1e-4);
  const CommandResult ana =
      Cli({"submit", scene, "--label", "team=flow", "--label", "owner=ana.b@lab"});
  ASSERT_EQ(ana.exit_code, 0) << ana.output;
  const CommandResult bo = Cli({"submit", scene, "--label", "owner=bo"});
  ASSERT_EQ(bo.exit_code, 0) << bo.output;
  const std::string ana_id = IdFrom(ana);

  const nlohmann::json listed = CliJson({"list", "--label", "owner=ana.b@lab"});
  ASSERT_EQ(listed["jobs"].size(), 1u) << listed.dump();
  EXPECT_EQ(listed["jobs"][0]["id"], ana_id);
  EXPECT_EQ(listed["jobs"][0]["labels"]["team"], "flow");
  EXPECT_EQ(CliJson({"list", "--label", "team=flow", "--label", "owner=bo"})
                .value("jobs", nlohmann::json::array())
                .size(),
            0u);
  EXPECT_EQ(CliJson({"list"})["jobs"].size(), 2u);
  // A calibration job carries labels too.
  const CommandResult calibration =
      Cli({"calibrate", std::string(SEEP_EXAMPLES_DIR) + "/calibration_sweep.textproto", "--label",
           "team=calibration"});
  ASSERT_EQ(calibration.exit_code, 0) << calibration.output;
  const nlohmann::json calibrations = CliJson({"list", "--label", "team=calibration"});
  ASSERT_EQ(calibrations["jobs"].size(), 1u) << calibrations.dump();
  EXPECT_EQ(calibrations["jobs"][0]["kind"], "JOB_KIND_CALIBRATION");
  ASSERT_EQ(WaitTerminal(IdFrom(calibration)).state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_FALSE(CliJson({"calibrations", "--job", IdFrom(calibration)})
                   .value("records", nlohmann::json::array())
                   .empty());
  ASSERT_EQ(Cli({"delete", IdFrom(calibration)}).exit_code, 0);  // with its calibration records
  EXPECT_TRUE(CliJson({"calibrations", "--job", IdFrom(calibration)})
                  .value("records", nlohmann::json::array())
                  .empty());
  const CommandResult shown = Cli({"show", ana_id});
  EXPECT_NE(shown.output.find("labels    owner=ana.b@lab,team=flow"), std::string::npos)
      << shown.output;

  // Refused by the server naming the label; nothing stored.
  const CommandResult bad_key = Cli({"submit", scene, "--label", "Team=flow"});
  EXPECT_EQ(bad_key.exit_code, 3) << bad_key.output;
  EXPECT_NE(bad_key.output.find("labels[\"Team\"]: the key must be lower-case letters"),
            std::string::npos)
      << bad_key.output;
  const CommandResult bad_value = Cli({"submit", scene, "--label", "owner=a b"});
  EXPECT_EQ(bad_value.exit_code, 3) << bad_value.output;
  EXPECT_NE(bad_value.output.find("labels[\"owner\"]: the value 'a b' may hold only"),
            std::string::npos)
      << bad_value.output;
  const CommandResult bad_filter = Cli({"list", "--label", "x y=1"});
  EXPECT_EQ(bad_filter.exit_code, 3) << bad_filter.output;
  EXPECT_NE(bad_filter.output.find("labels[\"x y\"]"), std::string::npos) << bad_filter.output;
  // Refused by the CLI before any call.
  const CommandResult no_equals = Cli({"submit", scene, "--label", "owner"});
  EXPECT_EQ(no_equals.exit_code, 3);
  EXPECT_NE(no_equals.output.find("--label owner: expected KEY=VALUE"), std::string::npos)
      << no_equals.output;
  const CommandResult twice = Cli({"submit", scene, "--label", "a=1", "--label", "a=2"});
  EXPECT_EQ(twice.exit_code, 3);
  EXPECT_NE(twice.output.find("the key 'a' is given twice"), std::string::npos) << twice.output;
  EXPECT_EQ(CliJson({"list"})["jobs"].size(), 2u);
}

TEST_F(ServiceOperations, PageTokensAreOpaqueAndBoundToTheirFilters) {
  Start("data", {"--workers", "1"});
  for (int i = 0; i < 3; ++i) Submit(LatticeScene("paged-" + std::to_string(i), 1e-4));
  Submit(LatticeScene("other", 1e-4));
  const auto list = [&](const std::string& name, const std::string& token,
                        v1::ListJobsResponse* out) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::ListJobsRequest request;
    request.set_page_size(1);
    request.set_name_contains(name);
    request.set_page_token(token);
    return stub_->ListJobs(&ctx, request, out);
  };
  std::vector<std::string> names;
  std::string token;
  v1::ListJobsResponse page;
  do {
    page.Clear();
    ASSERT_TRUE(list("paged", token, &page).ok());
    for (const auto& job : page.jobs()) names.push_back(job.name());
    token = page.next_page_token();
    if (!token.empty()) {
      // Opaque: not the bare row number it used to be.
      EXPECT_FALSE(std::regex_match(token, std::regex("[0-9]+"))) << token;
      v1::ListJobsResponse other;
      const grpc::Status reused = list("other", token, &other);
      EXPECT_EQ(reused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
      EXPECT_NE(reused.error_message().find("page_token: was returned by ListJobs for other "
                                            "filters"),
                std::string::npos)
          << reused.error_message();
    }
  } while (!token.empty());
  EXPECT_EQ(names, (std::vector<std::string>{"paged-2", "paged-1", "paged-0"}));
  const grpc::Status forged = list("paged", "2", &page);
  EXPECT_EQ(forged.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(forged.error_message(), "page_token: not a token returned by ListJobs");
}

TEST_F(ServiceOperations, DeleteRemovesAFinishedJobAndItsFilesAndRefusesARunningOne) {
  Start("data", {"--workers", "1", "--checkpoint-every-steps", "200"});
  const std::string done = Submit(LatticeScene("finished", 3e-3));
  ASSERT_EQ(WaitTerminal(done).state(), v1::JOB_STATE_SUCCEEDED);
  ASSERT_FALSE(CheckpointFiles(done).empty());
  const std::string running = Submit(LatticeScene("running", 10.0));
  ASSERT_EQ(WaitRunningPast(running, 0).state(), v1::JOB_STATE_RUNNING);

  const CommandResult refused = Cli({"delete", running});
  EXPECT_EQ(refused.exit_code, 9) << refused.output;
  EXPECT_NE(refused.output.find("job " + running + " is RUNNING; only a finished job"),
            std::string::npos)
      << refused.output;
  EXPECT_EQ(Get(running).state(), v1::JOB_STATE_RUNNING);

  const std::size_t files = CheckpointFiles(done).size();
  const CommandResult deleted = Cli({"delete", done});
  EXPECT_EQ(deleted.exit_code, 0) << deleted.output;
  EXPECT_NE(deleted.output.find("job " + done + " deleted (" + std::to_string(files) +
                                " checkpoint file(s), "),
            std::string::npos)
      << deleted.output;
  EXPECT_FALSE(fs::exists(CheckpointFolder(done)));
  EXPECT_EQ(Cli({"show", done}).exit_code, 5);
  EXPECT_EQ(Cli({"delete", done}).exit_code, 5);
  EXPECT_EQ(Cli({"events", done}).exit_code, 5);
  EXPECT_EQ(Get(running).state(), v1::JOB_STATE_RUNNING);  // untouched
  EXPECT_FALSE(CheckpointFiles(running).empty());
}

// One job's life through `seep events`: submitted, claimed, checkpointed, interrupted by a
// shutdown, recovered at the next start, claimed again and resumed from the step of its newest
// checkpoint, finished.
TEST_F(ServiceOperations, EventsTellAJobsHistoryInOrder) {
  Start("data", {"--checkpoint-every-steps", "300"});
  // Long enough (about 95,000 steps, seconds in Release) to be seen running past step 700: a
  // worker process's progress reaches seepd once a second.
  const std::string id = Submit(LatticeScene("eventful", 2e-1));
  ASSERT_EQ(WaitRunningPast(id, 700).state(), v1::JOB_STATE_RUNNING);
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);
  Start("data", {"--checkpoint-every-steps", "300"});
  ASSERT_EQ(WaitTerminal(id).state(), v1::JOB_STATE_SUCCEEDED);

  const nlohmann::json events = CliJson({"events", id});
  ASSERT_TRUE(events.contains("events")) << events.dump();
  std::vector<std::string> kinds;
  google::protobuf::Timestamp previous;
  for (const auto& e : events["events"]) {
    kinds.push_back(e["kind"]);
    google::protobuf::Timestamp at;
    ASSERT_TRUE(google::protobuf::util::TimeUtil::FromString(e["at"], &at)) << e.dump();
    EXPECT_GE(at, previous) << "events out of order: " << events.dump(1);
    previous = at;
  }
  // The kinds in order, repeated checkpoints folded into one.
  std::vector<std::string> folded;
  for (const std::string& k : kinds) {
    if (folded.empty() || folded.back() != k) folded.push_back(k);
  }
  EXPECT_EQ(folded, (std::vector<std::string>{"SUBMITTED", "CLAIMED", "CHECKPOINT", "INTERRUPTED",
                                              "RECOVERED", "CLAIMED", "RESUMED", "CHECKPOINT",
                                              "SUCCEEDED"}))
      << events.dump(1);
  // The resume names the step of the last checkpoint before the shutdown.
  std::string last_checkpoint_before, resumed;
  for (const auto& e : events["events"]) {
    if (e["kind"] == "CHECKPOINT" && resumed.empty()) last_checkpoint_before = e["message"];
    if (e["kind"] == "RESUMED") resumed = e["message"];
  }
  std::smatch step;
  ASSERT_TRUE(std::regex_search(last_checkpoint_before, step, std::regex("^step ([0-9]+) ")))
      << last_checkpoint_before;
  EXPECT_NE(resumed.find(" at step " + step[1].str() + " of "), std::string::npos) << resumed;
  const CommandResult table = Cli({"events", id});
  EXPECT_EQ(table.exit_code, 0);
  EXPECT_EQ(table.output.rfind("TIME", 0), 0u) << table.output;
  EXPECT_NE(table.output.find("SUCCEEDED"), std::string::npos) << table.output;
}

// The e2e case of issue 17: with --retain-days and --retain-checkpoint-bytes, the next start
// deletes the finished jobs older than the limit (records and files), trims the superseded
// checkpoints of a recent finished job to fit the byte budget and keeps its final one (a small
// final state, kept in the store: it counts in the budget as a file would), and keeps every
// checkpoint of a running and of a queued job. On seepd's own threads (--isolation thread),
// whose small final states go into the store with the success (a worker process uploads its
// final state as a file, and the counts below are of files).
TEST_F(ServiceOperations, RetentionDeletesWhatItShouldAndNothingElse) {
  const std::vector<std::string> flags = {
      "--isolation",        "thread", "--workers", "1", "--checkpoint-every-steps", "300",
      "--checkpoints-kept", "3"};
  Start("data", flags);
  const std::string old_a = Submit(LatticeScene("old-a", 6e-3));
  const std::string old_b = Submit(LatticeScene("old-b", 1e-4));
  ASSERT_EQ(WaitTerminal(old_a).state(), v1::JOB_STATE_SUCCEEDED);
  ASSERT_EQ(WaitTerminal(old_b).state(), v1::JOB_STATE_SUCCEEDED);
  const std::int64_t old_finished = Get(old_a).finished_at().seconds();
  std::this_thread::sleep_for(std::chrono::seconds(5));
  const std::string fresh = Submit(LatticeScene("fresh", 6e-3));
  ASSERT_EQ(WaitTerminal(fresh).state(), v1::JOB_STATE_SUCCEEDED);
  const std::int64_t fresh_finished = Get(fresh).finished_at().seconds();
  ASSERT_GE(fresh_finished - old_finished, 4);
  const std::uint64_t fresh_final = FinalStateBytes(fresh);
  ASSERT_GT(fresh_final, 0u);
  // A job cancelled with checkpoints, resumed behind a running one: QUEUED at the restart.
  const std::string paused = Submit(LatticeScene("paused", 1.0));
  ASSERT_EQ(WaitRunningPast(paused, 700).state(), v1::JOB_STATE_RUNNING);
  ASSERT_EQ(Cli({"cancel", paused}).exit_code, 0);
  ASSERT_EQ(WaitTerminal(paused).state(), v1::JOB_STATE_CANCELLED);
  const std::string running = Submit(LatticeScene("running", 1.0));
  ASSERT_EQ(WaitRunningPast(running, 700).state(), v1::JOB_STATE_RUNNING);
  ASSERT_EQ(Cli({"resume", paused}).exit_code, 0);
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);

  const auto sizes = [&](const std::string& id) {
    std::map<std::string, std::uintmax_t> out;
    for (const std::string& name : CheckpointFiles(id)) {
      out[name] = fs::file_size(CheckpointFolder(id) / name);
    }
    return out;
  };
  const auto fresh_files = sizes(fresh);
  const auto running_files = sizes(running);
  const auto paused_files = sizes(paused);
  ASSERT_EQ(fresh_files.size(), 2u);  // and its final state in the store
  ASSERT_FALSE(running_files.empty());
  ASSERT_FALSE(paused_files.empty());
  ASSERT_FALSE(CheckpointFiles(old_a).empty());
  std::uintmax_t active = 0;
  for (const auto* files : {&running_files, &paused_files}) {
    for (const auto& [name, bytes] : *files) active += bytes;
  }
  // Room for the active jobs, fresh's final checkpoint and half of its second newest (its newest
  // file): its two files must go, its final state stays.
  const auto second = std::prev(fresh_files.end());
  const std::uintmax_t budget = active + fresh_final + second->second / 2;
  // Old jobs finished >= 4 s before fresh: a limit half-way between their ages.
  const double now = static_cast<double>(std::chrono::duration_cast<std::chrono::seconds>(
                                             std::chrono::system_clock::now().time_since_epoch())
                                             .count());
  const double limit_s = now - static_cast<double>(fresh_finished) + 2.0;
  std::vector<std::string> with_retention = flags;
  with_retention.insert(with_retention.end(), {"--retain-days", std::to_string(limit_s / 86400.0),
                                               "--retain-checkpoint-bytes", std::to_string(budget),
                                               "--checkpoint-interval-s", "0"});
  // No periodic checkpoints after the restart: the files the checks below see are those of the
  // retention at start.
  with_retention[3] = "0";
  Start("data", with_retention);

  for (const std::string& gone : {old_a, old_b}) {
    grpc::ClientContext ctx;
    v1::GetJobRequest request;
    request.set_id(gone);
    v1::GetJobResponse response;
    EXPECT_EQ(stub_->GetJob(&ctx, request, &response).error_code(), grpc::StatusCode::NOT_FOUND)
        << gone;
    EXPECT_FALSE(fs::exists(CheckpointFolder(gone))) << gone;
  }
  EXPECT_EQ(Get(fresh).state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_TRUE(CheckpointFiles(fresh).empty());
  EXPECT_EQ(FinalStateBytes(fresh), fresh_final);
  for (const auto& [id, files] : {std::pair{running, running_files}, {paused, paused_files}}) {
    for (const auto& [name, bytes] : files) {
      EXPECT_TRUE(fs::exists(CheckpointFolder(id) / name)) << id << "/" << name;
    }
  }
  const std::string log = Log();
  EXPECT_NE(log.find("retention: deleted 2 finished job(s) older than"), std::string::npos) << log;
  EXPECT_NE(log.find("and 2 checkpoint(s) of finished jobs over the budget of " +
                     std::to_string(budget) + " bytes"),
            std::string::npos)
      << log;
  const nlohmann::json events = CliJson({"events", fresh});
  EXPECT_EQ(events["events"].back()["kind"], "CHECKPOINTS_RETAINED") << events.dump(1);
  // Both active jobs run on from their checkpoints.
  EXPECT_NE(Get(running).state(), v1::JOB_STATE_FAILED);
  EXPECT_NE(Get(paused).state(), v1::JOB_STATE_FAILED);
}

// On seepd's own threads (--isolation thread), whose small final states go into the store (a
// worker process uploads its final state as a file): the count of steps below relies on it.
TEST_F(ServiceOperations, CheckpointFilesArePrivateSweptAtStartAndFollowAMovedDataFolder) {
  Start("data", {"--isolation", "thread", "--checkpoint-every-steps", "300"});
  const std::string id = Submit(LatticeScene("kept", 3e-3));
  ASSERT_EQ(WaitTerminal(id).state(), v1::JOB_STATE_SUCCEEDED);
  stub_.reset();
  ASSERT_EQ(server_.Stop(SIGTERM), 0);
  const std::set<std::string> files = CheckpointFiles(id);  // its final state is in the store
  ASSERT_FALSE(files.empty());
  EXPECT_EQ(fs::status(CheckpointFolder(id)).permissions() & fs::perms::all, fs::perms::owner_all);
  EXPECT_EQ(fs::status(dir_ / "data" / "checkpoints").permissions() & fs::perms::all,
            fs::perms::owner_all);
  for (const std::string& name : files) {
    EXPECT_EQ(fs::status(CheckpointFolder(id) / name).permissions() & fs::perms::all,
              fs::perms::owner_read | fs::perms::owner_write)
        << name;
  }
  // What a crash could leave: a file without its record, a half-written temporary file, the
  // folder of a job that is gone.
  std::ofstream(CheckpointFolder(id) / "ckpt-000000999999.bin") << "orphan";
  std::ofstream(CheckpointFolder(id) / "ckpt-000001000000.bin.tmp-a1B2c3") << "partial";
  fs::create_directories(dir_ / "data" / "checkpoints" / "j-0000000000000000");
  std::ofstream(dir_ / "data" / "checkpoints" / "j-0000000000000000" / "ckpt-000000000001.bin")
      << "x";

  fs::rename(dir_ / "data", dir_ / "moved");
  Start("moved", {"--isolation", "thread"});
  EXPECT_EQ(CheckpointFiles(id), files);
  EXPECT_FALSE(fs::exists(dir_ / "moved" / "checkpoints" / "j-0000000000000000"));
  EXPECT_NE(Log().find("removed 2 orphan file(s) (no checkpoint record), 1 temporary file(s) of "
                       "interrupted writes, 1 empty folder(s)"),
            std::string::npos)
      << Log();
  // Its checkpoint files are found in the moved folder: the fields at its newest file's step.
  const std::string newest = *files.rbegin();  // ckpt-<12 digits>.bin
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
  v1::GetJobFieldsRequest request;
  request.set_job_id(id);
  request.set_step(std::stoull(newest.substr(5, 12)));
  v1::GetJobFieldsResponse response;
  const grpc::Status fields = stub_->GetJobFields(&ctx, request, &response);
  ASSERT_TRUE(fields.ok()) << fields.error_message();
  EXPECT_EQ(response.step(), request.step());
  EXPECT_EQ(static_cast<std::size_t>(response.available_steps_size()), files.size() + 1);
  EXPECT_GT(response.fields().domain_pressure_pa_size(), 0);
}

// A worker stuck in a step (--test-stall-job: deaf to shutdown) holds the drain up: health says
// NOT_SERVING meanwhile, and --shutdown-timeout-s ends the process (status 3). The job was left
// RUNNING; the next start queues it again and it finishes.
TEST_F(ServiceOperations, HealthIsNotServingWhileDrainingAndTheTimeLimitEndsTheDrain) {
  const std::vector<std::string> flags = {
      "--isolation",          "thread", "--lease-s", "600", "--test-stall-job", "stuck",
      "--shutdown-timeout-s", "2"};
  Start("data", flags);
  EXPECT_EQ(Health(), grpc::health::v1::HealthCheckResponse::SERVING);
  const std::string id = Submit(LatticeScene("stuck", 1.5e-2));
  ASSERT_TRUE(WaitForLog("this worker stops making progress", std::chrono::seconds(60))) << Log();
  const auto sent = std::chrono::steady_clock::now();
  ASSERT_EQ(::kill(server_.pid(), SIGTERM), 0);
  ASSERT_TRUE(WaitForLog("signal 15 received: shutting down", std::chrono::seconds(5))) << Log();
  EXPECT_EQ(Health(), grpc::health::v1::HealthCheckResponse::NOT_SERVING);
  EXPECT_EQ(server_.PollExit(), -1);  // still draining, still answering
  EXPECT_EQ(WaitForExit(std::chrono::seconds(20)), 3);
  EXPECT_GE(std::chrono::steady_clock::now() - sent, std::chrono::milliseconds(1900));
  EXPECT_NE(Log().find("shutdown did not finish within 2 s (--shutdown-timeout-s): exiting now"),
            std::string::npos)
      << Log();
  Start("data", {});
  const v1::Job done = WaitTerminal(id);
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.DebugString();
}

TEST_F(ServiceOperations, ASecondSignalEndsTheDrainAtOnce) {
  // Default limit: 60 s.
  Start("data", {"--isolation", "thread", "--lease-s", "600", "--test-stall-job", "stuck"});
  Submit(LatticeScene("stuck", 1.5e-2));
  ASSERT_TRUE(WaitForLog("this worker stops making progress", std::chrono::seconds(60))) << Log();
  ASSERT_EQ(::kill(server_.pid(), SIGINT), 0);
  ASSERT_TRUE(WaitForLog("signal 2 received: shutting down", std::chrono::seconds(5))) << Log();
  EXPECT_EQ(Health(), grpc::health::v1::HealthCheckResponse::NOT_SERVING);
  const auto second = std::chrono::steady_clock::now();
  ASSERT_EQ(::kill(server_.pid(), SIGTERM), 0);
  EXPECT_EQ(WaitForExit(std::chrono::seconds(10)), 3);
  EXPECT_LT(std::chrono::steady_clock::now() - second, std::chrono::seconds(3));
  EXPECT_NE(Log().find("second signal 15 received: exiting now"), std::string::npos) << Log();
}

// A store failure reaches the client as the operation that failed, never as SQL: here the
// events table is dropped behind seepd's back.
TEST_F(ServiceOperations, AStoreFailureShowsTheOperationAndNoSql) {
  Start("data", {});
  const std::string id = Submit(LatticeScene("broken", 1e-4));
  ASSERT_EQ(WaitTerminal(id).state(), v1::JOB_STATE_SUCCEEDED);
  const CommandResult drop =
      RunCommand({"/usr/bin/sqlite3", (dir_ / "data" / "seep.db").string(), "DROP TABLE events;"});
  ASSERT_EQ(drop.exit_code, 0) << drop.output;
  const CommandResult events = Cli({"events", id});
  EXPECT_EQ(events.exit_code, 13) << events.output;  // INTERNAL
  EXPECT_NE(events.output.find("seep: events: store: list events failed: "), std::string::npos)
      << events.output;
  for (const char* leak : {"SELECT", "FROM", "no such table", "job_id"}) {
    EXPECT_EQ(events.output.find(leak), std::string::npos) << leak << " in " << events.output;
  }
  // seepd's log has the whole story.
  EXPECT_NE(Log().find("no such table: events"), std::string::npos);
}

}  // namespace
}  // namespace seep::testing
