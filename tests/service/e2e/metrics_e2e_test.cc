// seepd --metrics-listen through the real binary: GET /metrics (cpp-httplib's client, as curl
// would) before and after a job runs shows the counters moving: RPCs by method and code, jobs by
// state, steps, checkpoints and their bytes.
#include <httplib.h>

#include <fstream>
#include <regex>

#include "grpc_seepd_fixture.h"
#include "test_support.h"

namespace seep::testing {
namespace {

// The value of one sample line ("name{labels} value"); -1 when the line is missing.
double Sample(const std::string& text, const std::string& series) {
  const std::size_t at = text.find("\n" + series + " ");
  if (at == std::string::npos) return -1;
  return std::stod(text.substr(at + series.size() + 2));
}

class MetricsEndpointTest : public GrpcSeepdTest {
 protected:
  MetricsEndpointTest() : GrpcSeepdTest("e2e-metrics") {}

  // The port seepd logged for its metrics endpoint.
  int MetricsPort(const std::string& data) {
    const std::regex logged("metrics for Prometheus on http://127\\.0\\.0\\.1:(\\d+)/metrics");
    std::smatch match;
    const std::string log = ReadFile(dir_ / (data + ".out"));
    if (!std::regex_search(log, match, logged)) return -1;
    return std::stoi(match[1].str());
  }

  std::string Scrape(int port, const char* path = "/metrics", int* status = nullptr) {
    httplib::Client client("127.0.0.1", port);
    client.set_read_timeout(10, 0);
    const auto response = client.Get(path);
    EXPECT_TRUE(response) << "no answer from the metrics endpoint";
    if (!response) return "";
    if (status != nullptr) *status = response->status;
    return response->body;
  }
};

TEST_F(MetricsEndpointTest, CountersMoveWhenAJobRuns) {
  Start("metrics", {"--metrics-listen", "127.0.0.1:0", "--checkpoint-every-steps", "200"});
  const int port = MetricsPort("metrics");
  ASSERT_GT(port, 0) << ReadFile(dir_ / "metrics.out");

  int status = 0;
  const std::string before = Scrape(port, "/metrics", &status);
  EXPECT_EQ(status, 200);
  EXPECT_NE(before.find("# TYPE seep_rpc_requests_total counter"), std::string::npos) << before;
  EXPECT_EQ(Sample(before, "seep_jobs{state=\"SUCCEEDED\"}"), 0) << before;
  EXPECT_EQ(Sample(before, "seep_steps_total"), 0) << before;

  // The 1D transient example: about 1500 steps, checkpointed every 200.
  const std::string id = Submit(ExampleScene("transient_1d.textproto"));
  auto jobs = WaitAllTerminal({id}, std::chrono::seconds(120));
  ASSERT_EQ(jobs[id].state(), v1::JOB_STATE_SUCCEEDED) << jobs[id].DebugString();

  const std::string after = Scrape(port);
  EXPECT_EQ(Sample(after, "seep_rpc_requests_total{method=\"SubmitJob\",code=\"OK\"}"), 1) << after;
  EXPECT_GE(Sample(after, "seep_rpc_requests_total{method=\"GetJob\",code=\"OK\"}"), 1) << after;
  EXPECT_EQ(Sample(after, "seep_jobs{state=\"SUCCEEDED\"}"), 1) << after;
  EXPECT_EQ(Sample(after, "seep_queue_depth"), 0) << after;
  EXPECT_GT(Sample(after, "seep_steps_total"), 0) << after;
  EXPECT_GE(Sample(after, "seep_checkpoints_total"), 1) << after;
  EXPECT_GT(Sample(after, "seep_checkpoint_bytes_total"), 0) << after;
  EXPECT_GE(Sample(after, "seep_checkpoint_write_seconds_count"), 1) << after;

  Scrape(port, "/other", &status);
  EXPECT_EQ(status, 404);
}

TEST_F(MetricsEndpointTest, AnAddressWithoutAPortIsRefusedByName) {
  const CommandResult result =
      RunCommand({SEEPD_PATH, "--listen", "127.0.0.1:0", "--data-dir", (dir_ / "bad").string(),
                  "--metrics-listen", "localhost"});
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("--metrics-listen: 'localhost' is not HOST:PORT"), std::string::npos)
      << result.output;
}

}  // namespace
}  // namespace seep::testing
