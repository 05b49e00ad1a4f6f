// The bounded fuzz run of issue 50 in CTest: 2,000 seeded requests against a real seepd with two
// workers, the invariants checked after every request and at the end (fuzz_session.h). The seed
// is SEEP_FUZZ_SEED when set (to replay a failure another seed found), else a fixed one, so the
// suite is deterministic; bench/service/service_fuzz_bench runs any seed for longer.
#include <gtest/gtest.h>

#include <cstdlib>
#include <iostream>

#include "../e2e/grpc_seepd_fixture.h"
#include "fuzz_session.h"

namespace seep::testing {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif

// The run's bound on seepd's resident memory, in the Release suite (ASan's shadow memory and
// quarantine are no measure of seepd's own). seepd peaked near 100 MiB over these requests, the
// largest of them (megabytes of repeated fields, sweeps of 10,000 jobs refused) included.
constexpr std::size_t kRssBoundBytes = std::size_t{256} << 20;

class RequestFuzz : public GrpcSeepdTest {
 protected:
  RequestFuzz() : GrpcSeepdTest("e2e-fuzz") {}
};

std::uint64_t FuzzSeed() {
  const char* text = std::getenv("SEEP_FUZZ_SEED");
  return text != nullptr ? std::strtoull(text, nullptr, 10) : 50;
}

TEST_F(RequestFuzz, TwoThousandSeededRequestsKeepSeepdsInvariants) {
  // The job time limit bounds what a valid but long scene (a mutated end time) may take; such a
  // job ends FAILED naming the limit, which the invariants accept and the report counts.
  Start("data", {"--workers", "2", "--job-time-limit-s", "5"});
  const int port = WaitForPortFile((dir_ / "data.port").string(), std::chrono::seconds(5));
  fuzz::FuzzOptions options;
  options.seed = FuzzSeed();
  options.requests = 2000;
  options.limits.max_disks = 20'000;
  options.limits.max_sweep_jobs = 64;
  options.rss_limit_bytes = kAddressSanitizer ? 0 : kRssBoundBytes;
  options.end_wait = std::chrono::seconds(kAddressSanitizer ? 120 : 30);
  fuzz::FuzzSession session(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()),
      server_.pid(), dir_ / "data", options);
  session.SendRequests();
  session.CheckEndings();
  std::cout << session.Report() << "  time budget: 60 s in Release"
            << (kAddressSanitizer ? " (this build: AddressSanitizer, RSS not bounded)" : "")
            << "\n";
  EXPECT_EQ(session.counts().requests, options.requests);
  EXPECT_GT(session.counts().jobs_accepted, 0u) << "no request was accepted: the bases are broken";
  EXPECT_TRUE(session.violations().empty()) << session.Report();
  EXPECT_EQ(server_.PollExit(), -1) << "seepd ended";
}

}  // namespace
}  // namespace seep::testing
