// Bounded growth through the real seepd: WatchJob streams beyond --max-watch-streams are refused
// (and a slot freed by a stream that ends is taken again), a stream limit that would leave no
// thread for other calls is refused at start, and a job reporting progress at every step keeps
// a time series of at most 1024 rows.
#include "grpc_seepd_fixture.h"
#include "test_support.h"

namespace seep::testing {
namespace {

// The 1D transient example (about 1500 steps) run `times` as long, progress reported at every
// step.
v1::Scene EveryStepScene(double times) {
  v1::Scene scene = ExampleScene("transient_1d.textproto");
  scene.mutable_solver()->set_progress_every(1);
  scene.mutable_solver()->set_end_time_s(times * scene.solver().end_time_s());
  return scene;
}

class ServerLimits : public GrpcSeepdTest {
 protected:
  ServerLimits() : GrpcSeepdTest("e2e-limits") {}

  struct Stream {
    std::unique_ptr<grpc::ClientContext> ctx = std::make_unique<grpc::ClientContext>();
    std::unique_ptr<grpc::ClientReader<v1::JobEvent>> reader;
  };
  Stream Watch(const std::string& id) {
    Stream stream;
    v1::WatchJobRequest request;
    request.set_id(id);
    stream.reader = stub_->WatchJob(stream.ctx.get(), request);
    return stream;
  }
};

TEST_F(ServerLimits, WatchStreamsBeyondTheLimitAreRefused) {
  Start("watch", {"--max-watch-streams", "1", "--rpc-threads", "8"});
  const std::string id = Submit(EveryStepScene(1e4));  // runs until seepd stops
  Stream first = Watch(id);
  v1::JobEvent event;
  ASSERT_TRUE(first.reader->Read(&event));

  Stream second = Watch(id);
  EXPECT_FALSE(second.reader->Read(&event));
  const grpc::Status refused = second.reader->Finish();
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(refused.error_message().find("WatchJob: 1 streams follow jobs already"),
            std::string::npos)
      << refused.error_message();
  EXPECT_NE(refused.error_message().find("--max-watch-streams"), std::string::npos);

  // The first stream ends: its slot is free again within the stream's one-second look.
  first.ctx->TryCancel();
  (void)first.reader->Finish();
  bool followed = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!followed && std::chrono::steady_clock::now() < deadline) {
    Stream again = Watch(id);
    followed = again.reader->Read(&event);
    again.ctx->TryCancel();
    (void)again.reader->Finish();
    if (!followed) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_TRUE(followed);
}

TEST_F(ServerLimits, AStreamLimitThatLeavesNoThreadsIsRefusedAtStart) {
  const CommandResult result =
      RunCommand({SEEPD_PATH, "--listen", "127.0.0.1:0", "--data-dir", (dir_ / "bad").string(),
                  "--max-watch-streams", "16", "--rpc-threads", "16"});
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("--max-watch-streams 16 must be below --rpc-threads 16"),
            std::string::npos)
      << result.output;
}

TEST_F(ServerLimits, ProgressAtEveryStepKeepsTheSeriesBounded) {
  Start("series", {});
  const std::string id = Submit(EveryStepScene(3));
  auto jobs = WaitAllTerminal({id}, std::chrono::seconds(120));
  ASSERT_EQ(jobs[id].state(), v1::JOB_STATE_SUCCEEDED) << jobs[id].DebugString();
  const v1::TimeSeries& series = jobs[id].result().series();
  ASSERT_GT(series.columns_size(), 1);
  const auto rows = static_cast<std::size_t>(series.values_size() / series.columns_size());
  const auto steps = static_cast<std::size_t>(jobs[id].progress().step());
  EXPECT_GT(steps, 2048u);  // at least one halving
  EXPECT_LE(rows, 1024u);
  EXPECT_GT(rows, 512u);
}

}  // namespace
}  // namespace seep::testing
