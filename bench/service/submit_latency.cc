// Figure 3 of seep_service_bench: submit-to-running latency with 1,000 jobs queued.
//
// With a deep queue a new job waits behind the jobs ahead of it; that wait is the queue's length
// times their run time, not the service's latency. What the service adds on a job's way to
// RUNNING is measured in its two parts, in process, with production settings (a JobStore file on
// disk with synchronous=FULL, SeepServiceImpl behind a real gRPC server on loopback, JobRunner
// with one worker and checkpoints at the default interval):
//   a. submit: the SubmitJob RPC round trip from a gRPC client (validation, durable insert,
//      wake-up), with >= `queued` jobs already QUEUED;
//   b. dequeue: from the moment the job becomes the head of the queue for a free worker (the
//      previous job's outcome committed, logged "succeeded") to the worker having claimed it
//      (QUEUED -> RUNNING with a lease in one transaction, lease renewed, live progress
//      published, logged "started"), while about `queued` jobs wait behind it.
// Timestamps of (b) come from the worker's own log lines through a capturing spdlog sink.
// (c) cross-checks end to end once the queue is emptied: SubmitJob to "started" with the worker
// idle and all those jobs in the store.
#include <fmt/format.h>
#include <grpcpp/grpcpp.h>
#include <spdlog/sinks/base_sink.h>

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <thread>

#include "jobs/job_hub.h"
#include "jobs/job_runner.h"
#include "jobs/store_ledger.h"
#include "rpc/seep_service.h"
#include "seep/v1/job_service.grpc.pb.h"
#include "service_bench.h"
#include "store/job_store.h"

namespace seep::bench {
namespace {

// When the worker's job loggers say "started" and "succeeded", in steady-clock time.
class WorkerEventSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  struct Event {
    Clock::time_point at;
    bool started = false;  // else succeeded (or any other end)
  };

  std::vector<Event> Events() {
    std::lock_guard lock(mutex_);
    return events_;
  }
  int Started() {
    std::lock_guard lock(mutex_);
    return started_;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    const auto now = Clock::now();
    const std::string_view logger(msg.logger_name.data(), msg.logger_name.size());
    if (logger.rfind("job-", 0) != 0) return;
    const std::string_view text(msg.payload.data(), msg.payload.size());
    if (text.rfind("started ", 0) == 0) {
      events_.push_back({now, true});
      ++started_;
    } else if (text.rfind("succeeded ", 0) == 0 || text.rfind("failed", 0) == 0) {
      events_.push_back({now, false});
    }
  }
  void flush_() override {}

 private:
  std::vector<Event> events_;  // guarded by the base sink's mutex_
  int started_ = 0;
};

struct Summary {
  double p50 = 0.0, p99 = 0.0, max = 0.0;
};

Summary Summarize(const std::vector<double>& ms) {
  return {Percentile(ms, 0.5), Percentile(ms, 0.99), Percentile(ms, 1.0)};
}

void PrintSummary(const char* label, const std::vector<double>& ms) {
  const Summary s = Summarize(ms);
  std::printf("  %-58s p50 %7.2f ms  p99 %7.2f ms  max %7.2f ms  (n = %zu)\n", label, s.p50, s.p99,
              s.max, ms.size());
}

}  // namespace

bool SubmitToRunningLatency(const BenchOptions& options) {
  std::printf("\n3. Submit-to-running latency with %d queued jobs (goal p99 <= 20 ms)\n",
              options.queued_jobs);
  const std::filesystem::path dir = options.dir / "submit-latency";
  std::filesystem::create_directories(dir);
  auto opened = service::JobStore::Open((dir / "seep.db").string());
  if (!opened.ok()) {
    std::printf("FATAL: JobStore::Open: %s\n", opened.status().ToString().c_str());
    return false;
  }
  service::JobStore& store = **opened;

  auto sink = std::make_shared<WorkerEventSink>();
  auto logger = std::make_shared<spdlog::logger>("seepd", sink);
  logger->set_level(spdlog::level::info);

  service::JobHub hub;
  service::JobRunnerOptions runner_options;
  runner_options.workers = 1;
  runner_options.build_id = options.build_id;
  runner_options.lease_owner = "seep-service-bench";
  runner_options.checkpoints.enabled = true;
  service::StoreLedger ledger(store, dir / "checkpoints", logger);
  runner_options.checkpoints.interval =
      std::chrono::milliseconds(static_cast<std::int64_t>(options.default_interval_s * 1000.0));
  service::JobRunner runner(ledger, &store, hub, runner_options, logger);
  service::PhysicsPool physics(1, 1, 16);
  service::SeepServiceImpl service_impl(
      store, hub, physics, options.build_id,
      {[&] { runner.Wake(); }, [&](const std::string& id) { runner.CancelRunning(id); }}, logger);
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(&service_impl);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) {
    std::printf("FATAL: cannot start the gRPC server on 127.0.0.1:0\n");
    return false;
  }
  auto channel =
      grpc::CreateChannel(fmt::format("127.0.0.1:{}", port), grpc::InsecureChannelCredentials());
  auto stub = v1::SeepService::NewStub(channel);

  int submitted = 0;
  std::vector<Clock::time_point> submit_done;  // when each submit returned
  const auto submit = [&](std::vector<double>* latencies_ms) {
    v1::SubmitJobRequest request;
    *request.mutable_scene() = QuickSteadyScene(fmt::format("bench-quick-{}", submitted));
    request.set_request_id(fmt::format("r-bench-{}", submitted));
    v1::SubmitJobResponse response;
    grpc::ClientContext context;
    const auto t0 = Clock::now();
    const grpc::Status status = stub->SubmitJob(&context, request, &response);
    const auto t1 = Clock::now();
    if (!status.ok() || !response.created()) {
      std::printf("FATAL: SubmitJob: %s\n", status.error_message().c_str());
      std::exit(1);
    }
    ++submitted;
    submit_done.push_back(t1);
    if (latencies_ms != nullptr) latencies_ms->push_back(Millis(t0, t1));
  };

  // Fill the queue (the worker is not started yet, so they all stay QUEUED).
  std::vector<double> fill_ms;
  const auto f0 = Clock::now();
  for (int i = 0; i < options.queued_jobs; ++i) submit(&fill_ms);
  std::printf("  queue filled: %d jobs QUEUED through SubmitJob in %.1f s\n", options.queued_jobs,
              Seconds(f0, Clock::now()));

  // (a0) With the queue full and the worker not writing to the store (as while it is inside a
  // long job: one progress write a second), then (a) with the worker draining quick jobs back to
  // back, its claims and outcomes contending with the submits for the store (the worst case).
  std::vector<double> quiet_submit_ms;
  const int quiet_from = submitted;
  for (int i = 0; i < options.latency_samples; ++i) submit(&quiet_submit_ms);
  runner.Start();
  const auto run_start = Clock::now();
  std::vector<double> submit_ms;
  std::vector<int> depth_at_submit;
  for (int i = 0; i < options.latency_samples; ++i) {
    depth_at_submit.push_back(submitted - sink->Started());
    submit(&submit_ms);
  }
  // Let the worker go on until enough head-of-queue -> running transitions were seen.
  const int wanted_starts = options.latency_samples + 1;
  while (sink->Started() < wanted_starts && Seconds(run_start, Clock::now()) < 300.0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const double run_s = Seconds(run_start, Clock::now());
  runner.Stop();
  const int drained = sink->Started();

  // Dequeue latencies: each "started" right after an end of the previous job.
  const auto events = sink->Events();
  std::vector<double> dequeue_ms;
  std::vector<int> depth_at_dequeue;
  int starts_seen = 0;
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (!events[i].started) continue;
    ++starts_seen;
    if (i == 0 || events[i - 1].started) continue;  // the first claim has no predecessor
    dequeue_ms.push_back(Millis(events[i - 1].at, events[i].at));
    // Jobs still queued behind this one when it was claimed.
    int submitted_before = 0;
    for (const auto& t : submit_done) submitted_before += t <= events[i].at ? 1 : 0;
    depth_at_dequeue.push_back(submitted_before - starts_seen);
  }
  const auto [dmin, dmax] = std::minmax_element(depth_at_dequeue.begin(), depth_at_dequeue.end());
  const auto [smin, smax] = std::minmax_element(depth_at_submit.begin(), depth_at_submit.end());
  std::printf(
      "  worker: %d jobs claimed and run in %.1f s (%.1f jobs/s: each claim, steady solve, "
      "final checkpoint, result and outcome is several fsync'ed writes)\n",
      drained, run_s, drained / run_s);
  PrintSummary("SubmitJob while filling (0 .. queued ahead)", fill_ms);
  PrintSummary(fmt::format("(a0) SubmitJob RPC, {} .. {} queued, worker not writing", quiet_from,
                           submitted - options.latency_samples - 1)
                   .c_str(),
               quiet_submit_ms);
  PrintSummary(
      fmt::format("(a) SubmitJob RPC, {} .. {} queued, worker draining", *smin, *smax).c_str(),
      submit_ms);
  PrintSummary(fmt::format("(b) head of queue -> RUNNING, {} .. {} queued behind",
                           dequeue_ms.empty() ? 0 : *dmin, dequeue_ms.empty() ? 0 : *dmax)
                   .c_str(),
               dequeue_ms);
  // (a) and (b) happen to the same job at different times and are independent: the distribution
  // of their sum is the convolution of the two samples (every pair).
  const auto p99_of_sum = [&](const std::vector<double>& submit_sample, const char* label) {
    std::vector<double> sums;
    sums.reserve(submit_sample.size() * dequeue_ms.size());
    for (const double a : submit_sample) {
      for (const double b : dequeue_ms) sums.push_back(a + b);
    }
    PrintSummary(label, sums);
    return std::max(Percentile(sums, 0.99),
                    Percentile(submit_sample, 0.99) + Percentile(dequeue_ms, 0.99));
  };
  const double quiet =
      p99_of_sum(quiet_submit_ms, "(a0)+(b) submit-to-running, worker in long jobs");
  const double busy = p99_of_sum(submit_ms, "(a)+(b) submit-to-running, worker draining");
  const bool met = !dequeue_ms.empty() && busy <= 20.0;
  std::printf(
      "  definition: the service's own latency on a job's way to RUNNING, submit + dequeue, "
      "without the wait for the jobs ahead of it (their run time, not the service's); p99 of the "
      "sum over every pair of samples, or p99(submit) + p99(dequeue) if larger\n");
  std::printf(
      "  goal p99 <= 20 ms: worker in long jobs %.2f ms -> %s; worker draining %.2f ms -> %s\n",
      quiet, Verdict(quiet <= 20.0), busy, Verdict(met));
  // (c) Cross-check, end to end: the queue emptied (the jobs left are cancelled), the worker
  // idle, the store holding all those jobs; SubmitJob -> "started", one job at a time.
  const auto x0 = Clock::now();
  int cancelled = 0;
  service::JobFilter queued_only;
  queued_only.states = {service::JobState::kQueued};
  for (;;) {
    auto page = store.List(1000, std::nullopt, queued_only);
    if (!page.ok() || page->jobs.empty()) break;
    for (const auto& queued : page->jobs) {
      cancelled += store.Cancel(queued.id, 0).ok() ? 1 : 0;
    }
  }
  std::printf("  (%d queued jobs cancelled in %.1f s for (c))\n", cancelled,
              Seconds(x0, Clock::now()));
  runner.Start();
  std::vector<double> idle_ms, idle_submit_ms, idle_claim_ms;
  const int idle_samples = std::min(100, options.latency_samples);
  for (int i = 0; i < idle_samples; ++i) {
    const std::size_t seen = sink->Events().size();
    const int started_before = sink->Started();
    std::vector<double> rpc_ms;
    const auto t0 = Clock::now();
    submit(&rpc_ms);
    const auto deadline = t0 + std::chrono::seconds(10);
    // Wait for its start and its end, so that the worker is idle again for the next one.
    while (sink->Events().size() < seen + 2 && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    const auto after = sink->Events();
    if (sink->Started() != started_before + 1 || after.size() < seen + 1) continue;
    idle_ms.push_back(Millis(t0, after[seen].at));
    idle_submit_ms.push_back(rpc_ms.front());
    idle_claim_ms.push_back(Millis(submit_done.back(), after[seen].at));
  }
  runner.Stop();
  server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  PrintSummary(
      fmt::format("(c) idle worker, {} jobs stored: SubmitJob -> RUNNING", submitted).c_str(),
      idle_ms);
  PrintSummary("    of which the SubmitJob RPC", idle_submit_ms);
  PrintSummary("    of which RPC returned -> RUNNING (wake-up, claim)", idle_claim_ms);
  return met;
}

}  // namespace seep::bench
