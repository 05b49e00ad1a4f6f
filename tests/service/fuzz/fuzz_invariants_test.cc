// The fuzzer's checks can fail: the refusal rule on messages that name a field and on ones that
// do not, and on a real seepd each invariant planted broken (a job stored behind the fuzzer's
// back, an RSS bound below what seepd uses, a queue no worker drains, seepd killed) is reported
// with the seed and request.
#include <gtest/gtest.h>

#include "../e2e/grpc_seepd_fixture.h"
#include "fuzz_session.h"
#include "refusal_rule.h"

namespace seep::testing {
namespace {

const google::protobuf::Descriptor& SubmitJobType() { return *v1::SubmitJobRequest::descriptor(); }

TEST(RefusalRule, APathOfTheRequestsFieldsPasses) {
  for (const char* message :
       {"scene.packing.lattice.columns: must be at least 2",
        "scene.effects[1].walls.walls[0].side: set one", "labels[\"Key\"]: only lower-case",
        "scene.packing.random.target: set one", "scene.boundary.regions[1] ('b'): overlaps",
        "scene.packing.particles[2].radius_m: must be > 0", "from_step: only with from_job_id",
        "calibration.scene.aperture", "SubmitJob: the request's bytes do not decode as x"}) {
    EXPECT_EQ(fuzz::RefusalProblem(SubmitJobType(), "SubmitJob", "",
                                   {grpc::StatusCode::INVALID_ARGUMENT, message}),
              "")
        << message;
  }
}

TEST(RefusalRule, AMessageWithoutAFieldOrWithAnUnknownOneFails) {
  for (const char* message : {"invalid scene", "scene.packing.lattice.colums: misspelt",
                              "scene.name.first: a string has no fields", "", "scene[0: unclosed",
                              "GetJob: the request's bytes do not decode (another method's)"}) {
    EXPECT_NE(fuzz::RefusalProblem(SubmitJobType(), "SubmitJob", "",
                                   {grpc::StatusCode::INVALID_ARGUMENT, message}),
              "")
        << message;
  }
  // NOT_FOUND holds the id it did not find, or a field.
  EXPECT_EQ(fuzz::RefusalProblem(*v1::GetJobRequest::descriptor(), "GetJob", "j-1",
                                 {grpc::StatusCode::NOT_FOUND, "job j-1 not found"}),
            "");
  EXPECT_NE(fuzz::RefusalProblem(*v1::GetJobRequest::descriptor(), "GetJob", "j-1",
                                 {grpc::StatusCode::NOT_FOUND, "no such job"}),
            "");
  // INTERNAL is never a refusal.
  EXPECT_NE(fuzz::RefusalProblem(SubmitJobType(), "SubmitJob", "",
                                 {grpc::StatusCode::INTERNAL, "scene: internal error"}),
            "");
}

class FuzzInvariants : public GrpcSeepdTest {
 protected:
  FuzzInvariants() : GrpcSeepdTest("e2e-fuzz-planted") {}

  fuzz::FuzzSession Session(
      std::uint64_t requests, std::size_t rss_limit_bytes = 0,
      const std::function<void(fuzz::FuzzOptions&)>& adjust = [](fuzz::FuzzOptions&) {}) {
    const int port = WaitForPortFile((dir_ / "data.port").string(), std::chrono::seconds(5));
    fuzz::FuzzOptions options;
    options.seed = 7;
    options.requests = requests;
    options.rss_limit_bytes = rss_limit_bytes;
    options.end_wait = std::chrono::seconds(30);
    adjust(options);
    return fuzz::FuzzSession(grpc::CreateChannel("127.0.0.1:" + std::to_string(port),
                                                 grpc::InsecureChannelCredentials()),
                             server_.pid(), dir_ / "data", options);
  }

  static bool Reports(const fuzz::FuzzSession& session, const std::string& what) {
    for (const std::string& v : session.violations()) {
      if (v.find(what) != std::string::npos && v.rfind("seed 7 request ", 0) == 0) return true;
    }
    return false;
  }
};

TEST_F(FuzzInvariants, AJobStoredBehindTheFuzzersBackIsReported) {
  Start("data", {"--workers", "1"});
  fuzz::FuzzSession session = Session(60);
  Submit(LatticeScene("behind-its-back", 1e-4));
  session.SendRequests();
  EXPECT_TRUE(Reports(session, "the answers so far made")) << session.Report();
}

TEST_F(FuzzInvariants, AnRssBoundBelowSeepdsIsReported) {
  Start("data", {"--workers", "1"});
  fuzz::FuzzSession session = Session(5, /*rss_limit_bytes=*/1 << 20);
  session.SendRequests();
  EXPECT_TRUE(Reports(session, "over the bound of 1 MiB")) << session.Report();
}

TEST_F(FuzzInvariants, AQueueThatEndsNoJobIsReportedAndEndsTheRun) {
  Start("data", {"--workers", "0"});  // a coordinator whose jobs no worker runs
  fuzz::FuzzSession session = Session(200, 0, [](fuzz::FuzzOptions& options) {
    options.max_backlog = 2;
    options.stall = std::chrono::seconds(2);
  });
  session.SendRequests();
  EXPECT_TRUE(Reports(session, "and none ended for 2 s")) << session.Report();
  EXPECT_LT(session.counts().requests, 200u);
}

TEST_F(FuzzInvariants, AKilledSeepdIsReportedAndEndsTheRun) {
  Start("data", {"--workers", "1"});
  fuzz::FuzzSession session = Session(50);
  ASSERT_EQ(::kill(server_.pid(), SIGKILL), 0);
  // Not reaped: the fuzzer sees what an operator would (the process gone, a zombie).
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  session.SendRequests();
  EXPECT_TRUE(Reports(session, "is gone")) << session.Report();
  EXPECT_LT(session.counts().requests, 50u);
}

}  // namespace
}  // namespace seep::testing
