// seep_load_bench: many clients against a real seepd on loopback. Each client has its own
// channel and loops over submit (a steady job of a few milliseconds), list, watch (until the job
// ends) and get, for a fixed wall time; seepd's resident memory is sampled from /proc meanwhile.
// Prints the calls, errors, latencies and RSS figures, then PASS when no call failed and the RSS
// stayed bounded (its peak under the limit, and the second half of the run no more than 10 %
// above the first half's peak: memory that grows with the calls made would show there).
//
//   seep_load_bench [--clients 50] [--seconds 60] [--rss-limit-mib 512] [--seepd PATH]
#include <grpcpp/grpcpp.h>
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "call_book.h"
#include "child_process.h"
#include "seep/v1/job_service.grpc.pb.h"
#include "service_bench.h"

namespace seep::bench {
namespace {

struct LoadOptions {
  int clients = 50;
  double seconds = 60.0;
  double rss_limit_mib = 512.0;
  std::string seepd = SEEPD_PATH;
};

ChildProcess StartSeepd(const LoadOptions& options, const std::filesystem::path& dir) {
  return ChildProcess(
      {options.seepd, "--listen", "127.0.0.1:0", "--data-dir", (dir / "data").string(),
       "--port-file", (dir / "port").string(), "--workers", "2", "--log-level", "warn"},
      dir / "seepd.out");
}

void SetDeadline(grpc::ClientContext& ctx) {
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
}

// One client: its own channel, submit → list → watch → get until the deadline.
void ClientLoop(int client, int port, Clock::time_point until, CallBook& book,
                std::atomic<std::uint64_t>& jobs_done) {
  grpc::ChannelArguments args;
  args.SetInt("seep.client", client);  // a channel of its own, not shared with the others
  auto channel = grpc::CreateCustomChannel("127.0.0.1:" + std::to_string(port),
                                           grpc::InsecureChannelCredentials(), args);
  auto stub = v1::SeepService::NewStub(channel);
  for (int n = 0; Clock::now() < until; ++n) {
    v1::SubmitJobRequest submit;
    *submit.mutable_scene() = QuickSteadyScene("load-" + std::to_string(client));
    v1::SubmitJobResponse submitted;
    if (!Timed(book, "submit", [&] {
           grpc::ClientContext ctx;
           SetDeadline(ctx);
           return stub->SubmitJob(&ctx, submit, &submitted);
         }).ok()) {
      continue;
    }
    const std::string id = submitted.job().id();
    Timed(book, "list", [&] {
      grpc::ClientContext ctx;
      SetDeadline(ctx);
      v1::ListJobsRequest request;
      request.set_page_size(20);
      v1::ListJobsResponse response;
      return stub->ListJobs(&ctx, request, &response);
    });
    Timed(book, "watch", [&] {
      grpc::ClientContext ctx;
      SetDeadline(ctx);
      v1::WatchJobRequest request;
      request.set_id(id);
      auto reader = stub->WatchJob(&ctx, request);
      v1::JobEvent event;
      while (reader->Read(&event)) {
      }
      return reader->Finish();
    });
    Timed(book, "get", [&] {
      grpc::ClientContext ctx;
      SetDeadline(ctx);
      v1::GetJobRequest request;
      request.set_id(id);
      v1::GetJobResponse response;
      grpc::Status status = stub->GetJob(&ctx, request, &response);
      if (status.ok() && response.job().state() != v1::JOB_STATE_SUCCEEDED) {
        return grpc::Status(grpc::StatusCode::INTERNAL,
                            "job " + id + " ended " + v1::JobState_Name(response.job().state()));
      }
      return status;
    });
    ++jobs_done;
  }
}

int Run(const LoadOptions& options) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("seep-load-bench-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ChildProcess seepd = StartSeepd(options, dir);
  const int port = seepd.started() ? WaitForPortFile(dir / "port") : -1;
  if (port <= 0) {
    std::fprintf(stderr, "seep_load_bench: seepd (%s) did not start; see %s\n",
                 options.seepd.c_str(), (dir / "seepd.out").c_str());
    return 2;
  }
  std::printf(
      "seep_load_bench: %d clients x %.0f s of submit/list/watch/get against seepd pid %d "
      "on 127.0.0.1:%d\n",
      options.clients, options.seconds, seepd.pid(), port);
  const double rss_start = seepd.RssMib();
  CallBook book;
  std::atomic<std::uint64_t> jobs_done{0};
  const auto start = Clock::now();
  const auto until = start + std::chrono::milliseconds(static_cast<int>(options.seconds * 1000));
  std::vector<std::thread> clients;
  for (int c = 0; c < options.clients; ++c) {
    clients.emplace_back([&, c] { ClientLoop(c, port, until, book, jobs_done); });
  }
  // RSS every 250 ms: the peaks of the first and the second half of the run.
  double first_half_peak = 0.0;
  double second_half_peak = 0.0;
  while (Clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    double& peak =
        Seconds(start, Clock::now()) < options.seconds / 2 ? first_half_peak : second_half_peak;
    peak = std::max(peak, seepd.RssMib());
  }
  for (auto& t : clients) t.join();
  const double elapsed = Seconds(start, Clock::now());
  const double rss_end = seepd.RssMib();
  const bool clean_exit = ExitedCleanly(seepd.Stop(SIGTERM));

  book.Print();
  const double peak = std::max(first_half_peak, second_half_peak);
  const bool no_errors = book.errors() == 0;
  const bool rss_bounded =
      peak <= options.rss_limit_mib && second_half_peak <= 1.10 * first_half_peak;
  std::printf("jobs       %llu submitted, watched to the end and read back (%.1f per second)\n",
              static_cast<unsigned long long>(jobs_done.load()),
              static_cast<double>(jobs_done.load()) / elapsed);
  std::printf("errors     %d   %s (goal: 0)\n", book.errors(), Verdict(no_errors));
  std::printf(
      "seepd RSS  start %.1f MiB, peak %.1f MiB in the first half, %.1f MiB in the "
      "second, %.1f MiB at the end   %s (goal: peak <= %.0f MiB, second half <= 1.1 x "
      "first)\n",
      rss_start, first_half_peak, second_half_peak, rss_end, Verdict(rss_bounded),
      options.rss_limit_mib);
  std::printf("seepd      stopped with SIGTERM: %s\n", clean_exit ? "exit 0" : "NOT clean");
  const bool met = no_errors && rss_bounded && clean_exit;
  std::printf("%s\n", Verdict(met));
  if (met) std::filesystem::remove_all(dir);
  return met ? 0 : 1;
}

}  // namespace
}  // namespace seep::bench

int main(int argc, char** argv) {
  seep::bench::LoadOptions options;
  CLI::App app{"seep_load_bench: many gRPC clients against a real seepd"};
  app.add_option("--clients", options.clients, "client threads, each with its own channel")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--seconds", options.seconds, "wall time of the load")
      ->check(CLI::Range(1.0, 3600.0))
      ->capture_default_str();
  app.add_option("--rss-limit-mib", options.rss_limit_mib, "largest seepd RSS that passes")
      ->capture_default_str();
  app.add_option("--seepd", options.seepd, "the seepd binary")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  return seep::bench::Run(options);
}
