// seep_load_bench: many clients against a real seepd on loopback. Each client has its own
// channel and loops over submit (a steady job of a few milliseconds), list, watch (until the job
// ends) and get, for a fixed wall time; seepd's resident memory is sampled from /proc meanwhile.
// Prints the calls, errors, latencies and RSS figures, then PASS when no call failed and the RSS
// stayed bounded (its peak under the limit, and the second half of the run no more than 10 %
// above the first half's peak: memory that grows with the calls made would show there).
//
//   seep_load_bench [--clients 50] [--seconds 60] [--rss-limit-mib 512] [--seepd PATH]
#include <fcntl.h>
#include <grpcpp/grpcpp.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "seep/v1/job_service.grpc.pb.h"
#include "service_bench.h"

extern char** environ;

namespace seep::bench {
namespace {

struct LoadOptions {
  int clients = 50;
  double seconds = 60.0;
  double rss_limit_mib = 512.0;
  std::string seepd = SEEPD_PATH;
};

// What every client thread adds to, per call kind.
class CallBook {
 public:
  void Add(const std::string& call, double millis, const grpc::Status& status) {
    std::lock_guard lock(mutex_);
    latencies_[call].push_back(millis);
    if (!status.ok()) {
      ++errors_[call];
      if (first_errors_.size() < 5) {
        first_errors_.push_back(call + ": " + std::to_string(status.error_code()) + " " +
                                status.error_message());
      }
    }
  }
  int errors() const {
    int total = 0;
    for (const auto& [call, n] : errors_) total += n;
    return total;
  }
  void Print() const {
    std::printf("%-10s %9s %7s %10s %10s %10s\n", "call", "count", "errors", "p50_ms", "p99_ms",
                "max_ms");
    for (const auto& [call, samples] : latencies_) {
      const auto e = errors_.find(call);
      std::printf("%-10s %9zu %7d %10.2f %10.2f %10.2f\n", call.c_str(), samples.size(),
                  e == errors_.end() ? 0 : e->second, Median(samples), Percentile(samples, 0.99),
                  *std::max_element(samples.begin(), samples.end()));
    }
    for (const auto& line : first_errors_) std::printf("error: %s\n", line.c_str());
  }

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::vector<double>> latencies_;
  std::map<std::string, int> errors_;
  std::vector<std::string> first_errors_;
};

// Resident set size of a process in MiB, from /proc/<pid>/status; 0 when unreadable.
double RssMib(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0.0;
}

pid_t StartSeepd(const LoadOptions& options, const std::filesystem::path& dir) {
  const std::string data = (dir / "data").string();
  const std::string port_file = (dir / "port").string();
  const std::string log = (dir / "seepd.out").string();
  std::vector<std::string> args = {options.seepd, "--listen",    "127.0.0.1:0", "--data-dir",
                                   data,          "--port-file", port_file,     "--workers",
                                   "2",           "--log-level", "warn"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = -1;
  const int failed = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return failed == 0 ? pid : -1;
}

int WaitForPort(const std::filesystem::path& file) {
  for (int i = 0; i < 600; ++i) {
    std::ifstream in(file);
    int port = 0;
    if (in >> port && port > 0) return port;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return -1;
}

grpc::Status Timed(CallBook& book, const std::string& call,
                   const std::function<grpc::Status()>& fn) {
  const auto start = Clock::now();
  const grpc::Status status = fn();
  book.Add(call, Millis(start, Clock::now()), status);
  return status;
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
  const pid_t seepd = StartSeepd(options, dir);
  const int port = seepd > 0 ? WaitForPort(dir / "port") : -1;
  if (port <= 0) {
    std::fprintf(stderr, "seep_load_bench: seepd (%s) did not start; see %s\n",
                 options.seepd.c_str(), (dir / "seepd.out").c_str());
    if (seepd > 0) ::kill(seepd, SIGKILL);
    return 2;
  }
  std::printf(
      "seep_load_bench: %d clients x %.0f s of submit/list/watch/get against seepd pid %d "
      "on 127.0.0.1:%d\n",
      options.clients, options.seconds, seepd, port);
  const double rss_start = RssMib(seepd);
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
    peak = std::max(peak, RssMib(seepd));
  }
  for (auto& t : clients) t.join();
  const double elapsed = Seconds(start, Clock::now());
  const double rss_end = RssMib(seepd);
  ::kill(seepd, SIGTERM);
  int status = 0;
  ::waitpid(seepd, &status, 0);
  const bool clean_exit = WIFEXITED(status) && WEXITSTATUS(status) == 0;

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
