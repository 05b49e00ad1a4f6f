// Part 2 of seep_coordinator_bench: what running a sweep through the service costs against
// running its scenes back to back in process. The same `sweep_jobs` small transients (a lattice
// of sweep_columns x sweep_rows disks, explicit, to sweep_end_time_s; the jobs differ only in
// their inlet pressure, which leaves the work unchanged) run
//   a. in process: `lanes` threads of one core thread each take the scenes in turn and run each
//      as the runner does (DecodeScene, Simulation::Create, Run, Report), and nothing more:
//      no store, no checkpoint, no hash;
//   b. through the service: one sweep submitted to a pure coordinator (seepd --workers 0, its
//      default lease and checkpoint settings) and drained by `lanes` seep-worker processes on
//      loopback, each with one worker of one core thread (--workers 1 --threads-per-job 1), with
//      everything a job does there: claim, events, heartbeats, its final checkpoint uploaded and
//      written durably, result series and outcome stored.
// (b) is timed from the launch of the workers (the sweep is already queued: its submission is
// timed apart) to the last job's finished_at as seepd recorded it. Both ran the same physics:
// every job's metrics must equal its in-process run's. Limit (issue 18): (b) reaches >= 90 % of
// (a)'s jobs per second.
#include <fmt/format.h>
#include <google/protobuf/util/time_util.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <map>
#include <thread>
#include <vector>

#include "codec/scene_codec.h"
#include "coordinator_bench.h"
#include "seep/core/run/simulation.h"
#include "seep/core/threads.h"
#include "service_bench.h"

namespace seep::bench {
namespace {

using Metrics = std::map<std::string, double>;
using google::protobuf::util::TimeUtil;

struct InProcessRun {
  double seconds = 0.0;
  double mean_job_ms = 0.0;      // one job's run, set-up included, on one lane
  std::vector<Metrics> metrics;  // by position
  int failures = 0;
};

// The sweep's scenes as the service expands them: the base with each inlet pressure.
std::vector<v1::Scene> ScenesOf(const v1::Sweep& sweep) {
  std::vector<v1::Scene> scenes;
  for (const double pressure : sweep.axes(0).numbers()) {
    v1::Scene& scene = scenes.emplace_back(sweep.scene());
    scene.mutable_boundary()->set_inlet_pressure_pa(pressure);
  }
  return scenes;
}

InProcessRun RunInProcess(const std::vector<v1::Scene>& scenes, int lanes) {
  InProcessRun run;
  run.metrics.resize(scenes.size());
  std::atomic<std::size_t> next{0};
  std::atomic<int> failures{0};
  std::atomic<double> busy_s{0.0};
  const auto start = Clock::now();
  {
    std::vector<std::jthread> threads;
    for (int lane = 0; lane < lanes; ++lane) {
      threads.emplace_back([&] {
        core::SetCoreThreadsForThisThread(1);  // as seep-worker --threads-per-job 1
        const auto logger = QuietLogger("in-process");
        double busy = 0.0;
        for (std::size_t i = next++; i < scenes.size(); i = next++) {
          const auto job_start = Clock::now();
          auto spec = service::DecodeScene(scenes[i]);
          auto sim = spec.ok() ? core::Simulation::Create(*spec, logger)
                               : core::Result<core::Simulation>(spec.status());
          core::RunControl control;
          control.logger = logger;
          if (!sim.ok() || !sim->Run(control).ok()) {
            ++failures;
            continue;
          }
          for (const auto& [name, value] : sim->Report().metrics) run.metrics[i][name] = value;
          busy += Seconds(job_start, Clock::now());
        }
        busy_s += busy;
      });
    }
  }
  run.seconds = Seconds(start, Clock::now());
  run.failures = failures;
  run.mean_job_ms = 1e3 * busy_s / static_cast<double>(scenes.size());
  return run;
}

struct ServiceRun {
  double submit_s = 0.0;
  double seconds = 0.0;  // worker launch to the last finished_at
  std::vector<v1::SweepJob> jobs;
  bool clean = false;  // seepd and every worker exited 0 on SIGTERM
  // CPU seconds over the drain: where a lane's time went besides the physics.
  double seepd_cpu_s = 0.0;
  double workers_cpu_s = 0.0;
};

// True once no job of the sweep's seepd is QUEUED or RUNNING (a cheap query, asked every 100 ms:
// GetSweep of every job that often would cost seepd more than the workers' own calls).
bool Drained(v1::SeepService::Stub& stub) {
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  v1::ListJobsRequest request;
  request.set_page_size(1);
  request.add_states(v1::JOB_STATE_QUEUED);
  request.add_states(v1::JOB_STATE_RUNNING);
  v1::ListJobsResponse response;
  return stub.ListJobs(&ctx, request, &response).ok() && response.jobs().empty();
}

std::optional<ServiceRun> RunOnWorkers(const CoordinatorOptions& options, const v1::Sweep& sweep,
                                       double patience_s) {
  ServiceRun run;
  Seepd seepd(options, "sweep", {"--log-level", "warn"});
  if (seepd.port() <= 0) return std::nullopt;
  auto stub = v1::SeepService::NewStub(seepd.Channel(-1));
  const auto submit_start = Clock::now();
  const std::optional<v1::SweepStatus> submitted = SubmitSweep(*stub, sweep);
  if (!submitted) return std::nullopt;
  run.submit_s = Seconds(submit_start, Clock::now());

  const std::int64_t launch_ms = TimeUtil::TimestampToMilliseconds(TimeUtil::GetCurrentTime());
  const auto launch = Clock::now();
  const double seepd_cpu_start = seepd.process().CpuSeconds();
  std::vector<ChildProcess> workers;
  for (int w = 0; w < options.lanes; ++w) {
    workers.emplace_back(
        std::vector<std::string>{options.seep_worker, "--server", seepd.address(), "--workers", "1",
                                 "--threads-per-job", "1", "--log-level", "warn", "--name",
                                 fmt::format("bench-lane-{}", w)},
        options.dir / fmt::format("worker-{}.out", w));
  }
  while (!Drained(*stub)) {
    if (Seconds(launch, Clock::now()) > patience_s) {
      std::printf("the workers did not drain the sweep within %.0f s; see %s\n", patience_s,
                  options.dir.c_str());
      return std::nullopt;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  run.seepd_cpu_s = seepd.process().CpuSeconds() - seepd_cpu_start;
  for (const ChildProcess& worker : workers) run.workers_cpu_s += worker.CpuSeconds();
  run.clean = true;
  for (ChildProcess& worker : workers) run.clean = ExitedCleanly(worker.Stop(SIGTERM)) && run.clean;

  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
  v1::GetSweepRequest request;
  request.set_id(submitted->id());
  v1::GetSweepResponse response;
  if (!stub->GetSweep(&ctx, request, &response).ok()) return std::nullopt;
  run.jobs.assign(response.sweep().jobs().begin(), response.sweep().jobs().end());
  std::int64_t last_ms = launch_ms;
  for (const v1::SweepJob& job : run.jobs) {
    last_ms = std::max(last_ms, TimeUtil::TimestampToMilliseconds(job.job().finished_at()));
  }
  run.seconds = 1e-3 * static_cast<double>(last_ms - launch_ms);
  stub.reset();
  run.clean = seepd.Stop() && run.clean;
  return run;
}

// Jobs that did not succeed, or whose metrics differ from their in-process run's.
int Mismatches(const ServiceRun& service, const InProcessRun& local) {
  int bad = 0;
  for (const v1::SweepJob& job : service.jobs) {
    const Metrics mine(job.job().result().metrics().begin(), job.job().result().metrics().end());
    bad += job.job().state() != v1::JOB_STATE_SUCCEEDED || job.position() >= local.metrics.size() ||
           mine != local.metrics[job.position()];
  }
  return bad + static_cast<int>(local.metrics.size() - service.jobs.size());
}

}  // namespace

bool SweepThroughput(const CoordinatorOptions& options) {
  const v1::Scene base =
      TransientLatticeScene(options.sweep_columns, options.sweep_rows, options.sweep_end_time_s);
  const v1::Sweep sweep = InletPressureSweep(base, options.sweep_jobs);
  std::printf(
      "\n== 2. sweep throughput: %d explicit transients on a %u x %u lattice to t = %g s, %d "
      "lane(s) of one core thread, in process and on seep-worker processes\n",
      options.sweep_jobs, options.sweep_columns, options.sweep_rows, options.sweep_end_time_s,
      options.lanes);
  const InProcessRun local = RunInProcess(ScenesOf(sweep), options.lanes);
  const double local_rate = options.sweep_jobs / local.seconds;
  std::printf("in process %.2f s, %.1f jobs/s (one job %.2f ms on its lane; %d failed)\n",
              local.seconds, local_rate, local.mean_job_ms, local.failures);

  const std::optional<ServiceRun> service =
      RunOnWorkers(options, sweep, 60.0 + 20.0 * local.seconds);
  if (!service) return false;
  double claimed_s = 0.0;  // started_at to finished_at, summed
  for (const v1::SweepJob& job : service->jobs) {
    claimed_s +=
        1e-3 * static_cast<double>(TimeUtil::TimestampToMilliseconds(job.job().finished_at()) -
                                   TimeUtil::TimestampToMilliseconds(job.job().started_at()));
  }
  const double n = static_cast<double>(options.sweep_jobs);
  const double service_rate = n / service->seconds;
  const double lane_ms = 1e3 * service->seconds * options.lanes / n;
  std::printf(
      "submitted  the sweep in %.2f s (validated and stored in one transaction; not "
      "counted below)\n",
      service->submit_s);
  std::printf(
      "service    %.2f s, %.1f jobs/s; a job takes %.2f ms of a lane: %.2f ms claimed (claim to "
      "outcome stored) + %.2f ms between claims\n",
      service->seconds, service_rate, lane_ms, 1e3 * claimed_s / n, lane_ms - 1e3 * claimed_s / n);
  std::printf(
      "overhead   %.2f ms a job over its in-process run; CPU a job: seepd %.2f ms, the "
      "seep-worker processes %.2f ms (the in-process run: %.2f ms of its lane)\n",
      lane_ms - local.mean_job_ms, 1e3 * service->seepd_cpu_s / n, 1e3 * service->workers_cpu_s / n,
      local.mean_job_ms);
  const int mismatches = Mismatches(*service, local);
  std::printf(
      "results    %d of %d jobs SUCCEEDED with their in-process metrics; seepd and "
      "workers stopped with SIGTERM: %s   %s\n",
      options.sweep_jobs - mismatches, options.sweep_jobs, service->clean ? "exit 0" : "NOT clean",
      Verdict(mismatches == 0));
  const double ratio = service_rate / local_rate;
  const bool ratio_met = ratio >= options.throughput_ratio_limit;
  std::printf("ratio      service / in process = %.3f   %s (limit: >= %.2f)\n", ratio,
              Verdict(ratio_met), options.throughput_ratio_limit);
  const bool met = ratio_met && mismatches == 0 && local.failures == 0;
  std::printf("part 2     %s\n", Verdict(met));
  return met;
}

}  // namespace seep::bench
