// Part 1 of seep_coordinator_bench: the coordinator's own cost under a deep queue and many
// remote workers. A pure coordinator (seepd --workers 0) holds `queued_jobs` queued simulation
// jobs (one sweep, submitted before anything is measured); `simulated_workers` threads, each with
// its own gRPC channel, speak the real seep.v1.WorkerService as seep-worker's runner does for a
// job, without the physics: ClaimJob (which records the CLAIMED event itself), then a KeepLease
// stream beating every heartbeat_s (progress on every other beat), and after a number of beats
// drawn per job around heartbeats_per_job (from half of it to one and a half times it, so that
// the workers' claims do not fall in step) the stream closed, StoreResultSeries with the final
// progress and FinishJob SUCCEEDED, then the next claim. Their starts are spread over one heartbeat
// interval, as independent workers' would be; a worker whose job would outlast the window stops
// there (it claims nothing more). Over the measured window (after a warm-up in which every worker
// takes its first job) seepd's CPU time is read from /proc/<pid>/stat, and every call's latency is
// recorded from the client side. Limits (issue 18): seepd CPU <= 5 % of one core, ClaimJob (the
// lease) p99 <= 20 ms, no failed call.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <random>
#include <thread>
#include <vector>

#include "call_book.h"
#include "coordinator_bench.h"
#include "seep/v1/worker_service.grpc.pb.h"
#include "service_bench.h"

namespace seep::bench {
namespace {

constexpr std::uint32_t kLeaseMs = 30'000;  // seep-worker's default --lease-s

// The measured stretch of the run: a call is recorded when it starts inside it.
struct Window {
  Clock::time_point start;
  Clock::time_point end;
  bool Holds(Clock::time_point t) const { return t >= start && t < end; }
};

void SetDeadline(grpc::ClientContext& ctx) {
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
}

// What a simulated worker's job reports: a few rows of a time series and one metric.
v1::Progress ProgressAt(int heartbeat, int heartbeats) {
  v1::Progress progress;
  progress.set_step(100 * static_cast<std::uint64_t>(heartbeat));
  progress.set_time_s(1e-4 * heartbeat);
  progress.set_fraction_done(static_cast<double>(heartbeat) / heartbeats);
  (*progress.mutable_latest())["inflow_m2_per_s"] = 1e-6;
  return progress;
}

class SimulatedWorker {
 public:
  SimulatedWorker(int index, const Seepd& seepd, const CoordinatorOptions& options, Window window,
                  CallBook& book)
      : name_(fmt::format("bench-sim-{:03}", index)),
        stub_(v1::WorkerService::NewStub(seepd.Channel(index))),
        options_(options),
        window_(window),
        book_(book),
        random_(static_cast<std::uint32_t>(index)),
        lengths_(std::max(1, options.heartbeats_per_job / 2),
                 std::max(1, options.heartbeats_per_job + options.heartbeats_per_job / 2)) {}

  // Claims and runs jobs until the window ends; returns how many it finished inside it.
  int Run(Clock::time_point first_claim) {
    std::this_thread::sleep_until(first_claim);
    int finished = 0;
    while (Clock::now() < window_.end) {
      v1::ClaimJobResponse claimed;
      const grpc::Status status = Call("ClaimJob", [&](grpc::ClientContext& ctx) {
        v1::ClaimJobRequest request;
        request.set_worker(name_);
        request.set_lease_ms(kLeaseMs);
        return stub_->ClaimJob(&ctx, request, &claimed);
      });
      if (!status.ok() || !claimed.has_job()) {
        std::this_thread::sleep_for(Heartbeat());  // as an idle runner polls
        continue;
      }
      if (!RunJob(claimed.job())) break;  // the window ends, or a call failed (counted)
      if (window_.Holds(Clock::now())) ++finished;
    }
    return finished;
  }

 private:
  std::chrono::steady_clock::duration Heartbeat() const {
    return std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(options_.heartbeat_s));
  }

  // One timed call with a fresh context, recorded when it starts inside the window.
  template <typename Fn>
  grpc::Status Call(const char* name, Fn&& fn) {
    const bool record = window_.Holds(Clock::now());
    return Timed(
        book_, name,
        [&] {
          grpc::ClientContext ctx;
          SetDeadline(ctx);
          return fn(ctx);
        },
        record);
  }

  // The calls of one job; false when it stopped early (the window ended, or a call failed).
  bool RunJob(const v1::LeasedJob& job) {
    v1::LeaseRef lease;
    lease.set_job_id(job.id());
    lease.set_lease_epoch(job.lease_epoch());
    const int heartbeats = lengths_(random_);
    if (!KeepLease(lease, heartbeats)) return false;
    grpc::Status status = Call("StoreResultSeries", [&](grpc::ClientContext& ctx) {
      v1::StoreResultSeriesRequest request;
      *request.mutable_lease() = lease;
      request.add_columns("time_s");
      request.add_columns("inflow_m2_per_s");
      for (int row = 0; row < 10; ++row) {
        request.add_values(1e-5 * row);
        request.add_values(1e-6);
      }
      request.set_state_sha256(std::string(64, 'a'));
      request.mutable_final_progress()->set_step(static_cast<std::uint64_t>(heartbeats));
      request.mutable_final_progress()->set_fraction_done(1.0);
      v1::StoreResultSeriesResponse response;
      return stub_->StoreResultSeries(&ctx, request, &response);
    });
    if (!status.ok()) return false;
    status = Call("FinishJob", [&](grpc::ClientContext& ctx) {
      v1::FinishJobRequest request;
      *request.mutable_lease() = lease;
      request.set_state(v1::JOB_STATE_SUCCEEDED);
      v1::NamedValue* metric = request.add_metrics();
      metric->set_name("inflow_m2_per_s");
      metric->set_value(1e-6);
      request.set_wall_time_s(heartbeats * options_.heartbeat_s);
      v1::FinishJobResponse response;
      return stub_->FinishJob(&ctx, request, &response);
    });
    return status.ok();
  }

  // The job's heartbeats as seep-worker sends them: beats of one KeepLease stream, progress on
  // every other one; then the stream closed, as before FinishJob. Each beat's write is timed
  // ("beat"; it waits for no answer), the close too ("KeepLease close": seepd has handled every
  // beat when it returns). False when the window ended first or the stream failed.
  bool KeepLease(const v1::LeaseRef& lease, int heartbeats) {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60) +
                     std::chrono::duration_cast<std::chrono::system_clock::duration>(
                         std::chrono::duration<double>(heartbeats * options_.heartbeat_s)));
    auto stream = stub_->KeepLease(&ctx);
    auto next = Clock::now();
    bool open = true;
    for (int h = 1; h <= heartbeats && open; ++h) {
      next += Heartbeat();
      if (next >= window_.end) return false;  // the job stays RUNNING: seepd is stopped next
      std::this_thread::sleep_until(next);
      v1::LeaseBeat beat;
      *beat.mutable_lease() = lease;
      beat.set_lease_ms(kLeaseMs);
      if (h % 2 == 0) *beat.mutable_progress() = ProgressAt(h, heartbeats);
      open = Timed(
                 book_, "beat",
                 [&] {
                   return stream->Write(beat)
                              ? grpc::Status::OK
                              : grpc::Status(grpc::StatusCode::UNAVAILABLE, "the stream ended");
                 },
                 window_.Holds(Clock::now()))
                 .ok();
    }
    const grpc::Status closed = Timed(
        book_, "KeepLease close",
        [&] {
          if (open) stream->WritesDone();
          v1::LeaseNews news;
          while (stream->Read(&news)) {
          }
          return stream->Finish();
        },
        window_.Holds(Clock::now()));
    return open && closed.ok();
  }

  std::string name_;
  std::unique_ptr<v1::WorkerService::Stub> stub_;
  const CoordinatorOptions& options_;
  Window window_;
  CallBook& book_;
  std::mt19937 random_;  // seeded by the worker's index: every run draws the same lengths
  std::uniform_int_distribution<int> lengths_;  // heartbeats of a job
};

// The sweep's jobs by state, as seepd counts them.
v1::SweepCounts Counts(const Seepd& seepd, const std::string& sweep_id) {
  auto stub = v1::SeepService::NewStub(seepd.Channel(-1));
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
  v1::GetSweepRequest request;
  request.set_id(sweep_id);
  v1::GetSweepResponse response;
  if (!stub->GetSweep(&ctx, request, &response).ok()) return {};
  return response.sweep().counts();
}

}  // namespace

bool CoordinatorLoad(const CoordinatorOptions& options) {
  std::printf(
      "\n== 1. coordinator load: seepd --workers 0 with %d queued jobs, %d simulated workers "
      "heartbeating every %.1f s (%d heartbeats a job on average), %.0f s measured after %.0f s of "
      "warm-up\n",
      options.queued_jobs, options.simulated_workers, options.heartbeat_s,
      options.heartbeats_per_job, options.load_seconds, options.warmup_s);
  Seepd seepd(options, "load", {"--log-level", "warn"});
  if (seepd.port() <= 0) return false;
  std::optional<v1::SweepStatus> sweep;
  {
    auto stub = v1::SeepService::NewStub(seepd.Channel(-1));
    const auto start = Clock::now();
    sweep = SubmitSweep(
        *stub, InletPressureSweep(QuickSteadyScene("coordinator-load"), options.queued_jobs));
    if (!sweep) return false;
    std::printf("queued     %d jobs (one SubmitSweep) in %.2f s, before the measurement\n",
                sweep->jobs_size(), Seconds(start, Clock::now()));
  }

  CallBook book;
  const auto begin = Clock::now();
  const auto seconds = [](double s) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  };
  const Window window{begin + seconds(options.warmup_s),
                      begin + seconds(options.warmup_s + options.load_seconds)};
  std::atomic<int> finished{0};
  std::vector<std::jthread> workers;
  for (int w = 0; w < options.simulated_workers; ++w) {
    const auto first_claim = begin + seconds(options.heartbeat_s * w / options.simulated_workers);
    workers.emplace_back([&, w, first_claim] {
      SimulatedWorker worker(w, seepd, options, window, book);
      finished += worker.Run(first_claim);
    });
  }
  std::this_thread::sleep_until(window.start);
  const double cpu_start = seepd.process().CpuSeconds();
  // Per-second samples too: the busiest second shows a periodic task the mean would hide.
  double busiest = 0.0;
  double previous = cpu_start;
  auto tick = window.start;
  while (tick + seconds(1.0) <= window.end) {
    tick += seconds(1.0);
    std::this_thread::sleep_until(tick);
    const double now = seepd.process().CpuSeconds();
    busiest = std::max(busiest, now - previous);
    previous = now;
  }
  std::this_thread::sleep_until(window.end);
  const double cpu_end = seepd.process().CpuSeconds();
  const double wall = Seconds(window.start, Clock::now());
  const double rss = seepd.process().RssMib();
  workers.clear();  // joins
  std::size_t calls = 0;
  // Calls and beats: what seepd answers or handles one by one.
  for (const char* call :
       {"ClaimJob", "AddJobEvent", "beat", "KeepLease close", "StoreResultSeries", "FinishJob"}) {
    calls += book.Count(call);
  }
  const double call_rate = static_cast<double>(calls) / wall;
  const double floor_percent = options.floor_seconds > 0.0
                                   ? TrivialCallCpuPercent(seepd, options.simulated_workers,
                                                           call_rate, options.floor_seconds)
                                   : 0.0;
  const v1::SweepCounts counts = Counts(seepd, sweep->id());
  const bool clean = seepd.Stop();

  book.Print();
  const double cpu_percent = 100.0 * (cpu_end - cpu_start) / wall;
  const double lease_p99 = book.Percentile("ClaimJob", 0.99);
  const bool cpu_met = cpu_percent <= options.cpu_limit_percent;
  const bool lease_met = lease_p99 <= options.lease_p99_limit_ms;
  const bool no_errors = book.errors() == 0;
  std::printf(
      "jobs       %d finished in the window (%.1f a second); at the end %u queued, %u running, "
      "%u succeeded\n",
      finished.load(), finished.load() / wall, counts.queued(), counts.running(),
      counts.succeeded());
  std::printf("seepd      RSS %.1f MiB at the end of the window; stopped with SIGTERM: %s\n", rss,
              clean ? "exit 0" : "NOT clean");
  std::printf(
      "seepd CPU  %.2f %% of one core over %.1f s (%.2f CPU s; busiest second %.0f %%)   %s "
      "(limit: <= %.0f %%)\n",
      cpu_percent, wall, cpu_end - cpu_start, 100.0 * busiest, Verdict(cpu_met),
      options.cpu_limit_percent);
  if (options.floor_seconds > 0.0) {
    std::printf(
        "gRPC floor %.2f %% of one core for the same %.0f calls a second as grpc.health.v1 "
        "Check from %d channels (%.0f s after the window): %.0f us of seepd CPU a call for gRPC "
        "alone, %.0f us for the worker calls\n",
        floor_percent, call_rate, options.simulated_workers, options.floor_seconds,
        1e4 * floor_percent / call_rate, 1e4 * cpu_percent / call_rate);
  }
  std::printf(
      "lease p99  ClaimJob p99 %.2f ms (p50 %.2f, max %.2f over %zu claims)   %s (limit: <= "
      "%.0f ms)\n",
      lease_p99, book.Percentile("ClaimJob", 0.5), book.Percentile("ClaimJob", 1.0),
      book.Count("ClaimJob"), Verdict(lease_met), options.lease_p99_limit_ms);
  std::printf(
      "beats      %zu in the window (%.1f a second); their writes p50 %.3f ms, p99 %.3f ms\n",
      book.Count("beat"), book.Count("beat") / wall, book.Percentile("beat", 0.5),
      book.Percentile("beat", 0.99));
  std::printf("errors     %d   %s (limit: 0)\n", book.errors(), Verdict(no_errors));
  const bool met = cpu_met && lease_met && no_errors;
  std::printf("part 1     %s\n", Verdict(met));
  return met;
}

}  // namespace seep::bench
