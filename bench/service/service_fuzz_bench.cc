// seep_service_fuzz_bench: the request fuzzer of issue 50 (tests/service/fuzz) for as many
// requests as it is given, against a seepd it starts on a fresh data folder. Prints the counts
// (requests by method and code, jobs by ending) and every invariant that failed, each with its
// seed and request index; exits 1 when one did.
//
//   seep_service_fuzz_bench [--seed 1] [--requests 50000] [--rss-limit-mib 512] [--workers 2]
//                           [--job-time-limit-s 5] [--end-wait-s 120] [--max-disks 20000]
//                           [--max-sweep-jobs 64] [--max-backlog 100] [--seepd PATH]
#include <grpcpp/grpcpp.h>
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#include "child_process.h"
#include "fuzz_session.h"

namespace seep::bench {
namespace {

struct FuzzBenchOptions {
  std::uint64_t seed = 1;
  std::uint64_t requests = 50'000;
  double rss_limit_mib = 512.0;
  int workers = 2;
  double job_time_limit_s = 5.0;
  int end_wait_s = 120;
  std::uint64_t max_disks = 20'000;
  std::uint64_t max_sweep_jobs = 64;
  std::int64_t max_backlog = 100;
  std::string seepd = SEEPD_PATH;
};

int Run(const FuzzBenchOptions& options) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("seep-fuzz-bench-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ChildProcess seepd(
      {options.seepd, "--listen", "127.0.0.1:0", "--data-dir", (dir / "data").string(),
       "--port-file", (dir / "port").string(), "--workers", std::to_string(options.workers),
       "--job-time-limit-s", std::to_string(options.job_time_limit_s), "--log-level", "warn"},
      dir / "seepd.out");
  const int port = seepd.started() ? WaitForPortFile(dir / "port") : -1;
  if (port <= 0) {
    std::fprintf(stderr, "seep_service_fuzz_bench: seepd (%s) did not start; see %s\n",
                 options.seepd.c_str(), (dir / "seepd.out").c_str());
    return 2;
  }
  std::printf(
      "seep_service_fuzz_bench: seed %llu, %llu requests against seepd pid %d (%d "
      "workers, --job-time-limit-s %g) on 127.0.0.1:%d\n",
      static_cast<unsigned long long>(options.seed),
      static_cast<unsigned long long>(options.requests), seepd.pid(), options.workers,
      options.job_time_limit_s, port);
  fuzz::FuzzOptions fuzz;
  fuzz.seed = options.seed;
  fuzz.requests = options.requests;
  fuzz.rss_limit_bytes = static_cast<std::size_t>(options.rss_limit_mib * (1 << 20));
  fuzz.end_wait = std::chrono::seconds(options.end_wait_s);
  fuzz.progress = &std::cout;
  fuzz.limits.max_disks = options.max_disks;
  fuzz.limits.max_sweep_jobs = options.max_sweep_jobs;
  fuzz.max_backlog = options.max_backlog;
  fuzz::FuzzSession session(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()),
      seepd.pid(), dir / "data", fuzz);
  session.SendRequests();
  session.CheckEndings();
  std::cout << session.Report();
  const bool held = session.violations().empty();
  std::printf("%s\n", held ? "PASS: every invariant held" : "MISS: see the violations above");
  if (seepd.Stop(SIGTERM) >= 0 && held) std::filesystem::remove_all(dir);
  return held ? 0 : 1;
}

}  // namespace
}  // namespace seep::bench

int main(int argc, char** argv) {
  seep::bench::FuzzBenchOptions options;
  CLI::App app{"seep_service_fuzz_bench: seeded hostile requests against a real seepd"};
  app.add_option("--seed", options.seed, "the run's seed (a failure names it)")
      ->capture_default_str();
  app.add_option("--requests", options.requests, "requests to send")->capture_default_str();
  app.add_option("--rss-limit-mib", options.rss_limit_mib,
                 "bound on seepd's resident memory (0: measured only)")
      ->capture_default_str();
  app.add_option("--workers", options.workers, "seepd --workers")->capture_default_str();
  app.add_option("--job-time-limit-s", options.job_time_limit_s, "seepd --job-time-limit-s")
      ->capture_default_str();
  app.add_option("--end-wait-s", options.end_wait_s,
                 "seconds the accepted jobs get to end after the last request")
      ->capture_default_str();
  app.add_option("--max-disks", options.max_disks,
                 "scenes of more disks than this (up to the 20,000,000 admitted) are drawn again; "
                 "0 sends them too (issue 50 item 2: their set-up runs outside the time limit)")
      ->capture_default_str();
  app.add_option("--max-sweep-jobs", options.max_sweep_jobs,
                 "sweeps of more jobs than this (up to the 10,000 admitted) are drawn again; 0 "
                 "sends them too")
      ->capture_default_str();
  app.add_option("--max-backlog", options.max_backlog,
                 "before each request, wait while more jobs than this are queued or running "
                 "(0: never)")
      ->capture_default_str();
  app.add_option("--seepd", options.seepd, "the seepd binary")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  return seep::bench::Run(options);
}
