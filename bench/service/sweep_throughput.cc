// Part 2 of seep_coordinator_bench: what running a sweep through the service costs against
// running its scenes back to back in process. The same `sweep_jobs` small transients (a lattice
// of sweep_columns x sweep_rows disks, explicit, to sweep_end_time_s; the jobs differ only in
// their inlet pressure, which leaves the work unchanged) run
//   a. in process: `lanes` threads of one core thread each take the scenes in turn and run each
//      as the runner does (DecodeScene, Simulation::Create, Run, Report), and nothing more:
//      no store, no checkpoint, no hash;
//   b. on local workers (--sweep-on local or both): one sweep submitted to a seepd with `lanes`
//      workers of its own of one core thread each (--workers N --threads-per-job 1, its default
//      lease and checkpoint settings), with everything a job does there: its claim (with its
//      event), its final checkpoint, result series and outcome stored in one commit (synced
//      within the store's durability window);
//   c. on remote workers (--sweep-on remote or both): the same sweep on a pure coordinator
//      (seepd --workers 0) drained by `lanes` seep-worker processes on loopback, each with one
//      worker of one core thread, its checkpoint uploaded over gRPC.
// The in-process run (a) is split: half its scenes run before the service runs and half after,
// so that a drift of the machine's speed (on a shared virtual machine, some per cent over a
// minute) weighs on both sides alike. (b) is timed from the sweep's stored (SubmitSweep returned,
// or its first job started if that came first) to the last job's finished_at as seepd recorded it;
// (c) from the launch of the workers (the sweep is already queued: its submission is timed apart).
// All ran the same physics: every job's metrics must equal its in-process run's. Limit (issue 18:
// "a 1,000-job sweep of small scenes on local workers"): (b) reaches >= 90 % of (a)'s jobs per
// second; (c)'s ratio is printed beside it.
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
  int jobs = 0;
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

// Runs scenes [begin, end) in process and adds their figures to `run` (its metrics sized to
// every scene): the bench runs half before the service and half after it, so that a drift of
// the machine's speed over the minute the bench takes weighs on both sides alike.
void RunInProcess(const std::vector<v1::Scene>& scenes, std::size_t begin, std::size_t end,
                  int lanes, InProcessRun& run) {
  run.metrics.resize(scenes.size());
  std::atomic<std::size_t> next{begin};
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
        for (std::size_t i = next++; i < end; i = next++) {
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
  const double done = static_cast<double>(run.jobs);
  run.jobs += static_cast<int>(end - begin);
  run.seconds += Seconds(start, Clock::now());
  run.failures += failures;
  run.mean_job_ms = (run.mean_job_ms * done + 1e3 * busy_s) / static_cast<double>(run.jobs);
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

// True once no job of the sweep's seepd is QUEUED or RUNNING. Asked twice a second: the drain is
// timed by the jobs' finished_at, not by this poll, and each poll costs seepd about 2 ms of CPU
// while a thousand jobs are queued (a list by state sorts the jobs in those states), which every
// 100 ms was a per cent of the service's throughput taken by the bench itself. (GetSweep of every
// job would cost more still.)
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

// local: seepd's own workers run the sweep; else seep-worker processes on a pure coordinator.
std::optional<ServiceRun> RunOnWorkers(const CoordinatorOptions& options, const v1::Sweep& sweep,
                                       double patience_s, bool local) {
  ServiceRun run;
  std::vector<std::string> flags = {"--log-level", "warn"};
  if (local) {
    flags.insert(flags.end(),
                 {"--workers", std::to_string(options.lanes), "--threads-per-job", "1"});
  }
  Seepd seepd(options, local ? "sweep-local" : "sweep-remote", flags);
  if (seepd.port() <= 0) return std::nullopt;
  auto stub = v1::SeepService::NewStub(seepd.Channel(-1));
  const double seepd_cpu_before_submit = seepd.process().CpuSeconds();
  const auto submit_start = Clock::now();
  const std::optional<v1::SweepStatus> submitted = SubmitSweep(*stub, sweep);
  if (!submitted) return std::nullopt;
  run.submit_s = Seconds(submit_start, Clock::now());

  // The system clock, as seepd's timestamps: protobuf's TimeUtil::GetCurrentTime() has whole
  // seconds in Debian's build, which put up to a second of nothing into the service's time.
  std::int64_t launch_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                               std::chrono::system_clock::now().time_since_epoch())
                               .count();
  const auto launch = Clock::now();
  // Local workers start with the submission: their CPU counts from before it.
  const double seepd_cpu_start = local ? seepd_cpu_before_submit : seepd.process().CpuSeconds();
  std::vector<ChildProcess> workers;
  for (int w = 0; w < (local ? 0 : options.lanes); ++w) {
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
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
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
  if (local) {  // timed from the sweep's stored, or its first start if that came first
    for (const v1::SweepJob& job : run.jobs) {
      launch_ms = std::min(launch_ms, TimeUtil::TimestampToMilliseconds(job.job().started_at()));
    }
  }
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

// One service run's figures against the in-process run; true when its results match and, if
// `judged`, its ratio meets the limit.
bool PrintServiceRun(const CoordinatorOptions& options, const ServiceRun& run,
                     const InProcessRun& local, double local_rate, bool on_local, bool judged) {
  const char* where = on_local ? "local" : "remote";
  double claimed_s = 0.0;  // started_at to finished_at, summed
  for (const v1::SweepJob& job : run.jobs) {
    claimed_s +=
        1e-3 * static_cast<double>(TimeUtil::TimestampToMilliseconds(job.job().finished_at()) -
                                   TimeUtil::TimestampToMilliseconds(job.job().started_at()));
  }
  const double n = static_cast<double>(options.sweep_jobs);
  const double service_rate = n / run.seconds;
  const double lane_ms = 1e3 * run.seconds * options.lanes / n;
  std::printf("-- on %s workers (%d %s)\n", where, options.lanes,
              on_local ? "workers of seepd's own" : "seep-worker processes of one worker each");
  std::printf(
      "submitted  the sweep in %.2f s (validated and stored in one transaction; not "
      "counted below)\n",
      run.submit_s);
  // A worker claims its next job while its last one's end is recorded, so a job's claim to
  // outcome can be longer than its share of a lane.
  std::printf(
      "service    %.2f s, %.1f jobs/s; a job takes %.2f ms of a lane; %.2f ms from its claim to "
      "its outcome stored (its end recorded while the lane runs the next job)\n",
      run.seconds, service_rate, lane_ms, 1e3 * claimed_s / n);
  if (on_local) {
    std::printf(
        "overhead   %.2f ms a job over its in-process run; CPU a job: seepd %.2f ms, its "
        "workers' physics included (the in-process run: %.2f ms of its lane)\n",
        lane_ms - local.mean_job_ms, 1e3 * run.seepd_cpu_s / n, local.mean_job_ms);
  } else {
    std::printf(
        "overhead   %.2f ms a job over its in-process run; CPU a job: seepd %.2f ms, the "
        "seep-worker processes %.2f ms (the in-process run: %.2f ms of its lane)\n",
        lane_ms - local.mean_job_ms, 1e3 * run.seepd_cpu_s / n, 1e3 * run.workers_cpu_s / n,
        local.mean_job_ms);
  }
  const int mismatches = Mismatches(run, local);
  std::printf(
      "results    %d of %d jobs SUCCEEDED with their in-process metrics; seepd and "
      "workers stopped with SIGTERM: %s   %s\n",
      options.sweep_jobs - mismatches, options.sweep_jobs, run.clean ? "exit 0" : "NOT clean",
      Verdict(mismatches == 0));
  const double ratio = service_rate / local_rate;
  const bool ratio_met = ratio >= options.throughput_ratio_limit;
  if (judged) {
    std::printf("ratio      %s workers / in process = %.3f   %s (limit: >= %.2f)\n", where, ratio,
                Verdict(ratio_met), options.throughput_ratio_limit);
  } else {
    std::printf(
        "ratio      %s workers / in process = %.3f (no limit: the issue's is on local "
        "workers)\n",
        where, ratio);
  }
  return mismatches == 0 && (!judged || ratio_met);
}

}  // namespace

bool SweepThroughput(const CoordinatorOptions& options) {
  const v1::Scene base =
      TransientLatticeScene(options.sweep_columns, options.sweep_rows, options.sweep_end_time_s);
  const v1::Sweep sweep = InletPressureSweep(base, options.sweep_jobs);
  std::printf(
      "\n== 2. sweep throughput: %d explicit transients on a %u x %u lattice to t = %g s, %d "
      "lane(s) of one core thread, in process and through the service (on %s workers)\n",
      options.sweep_jobs, options.sweep_columns, options.sweep_rows, options.sweep_end_time_s,
      options.lanes, options.sweep_on == "both" ? "local and remote" : options.sweep_on.c_str());
  // In process: the first half of the scenes before the service runs, the second after them.
  const std::vector<v1::Scene> scenes = ScenesOf(sweep);
  InProcessRun local;
  RunInProcess(scenes, 0, scenes.size() / 2, options.lanes, local);
  std::vector<std::pair<bool, ServiceRun>> services;
  for (const bool on_local : {true, false}) {
    if (options.sweep_on != "both" && (options.sweep_on == "local") != on_local) continue;
    std::optional<ServiceRun> service =
        RunOnWorkers(options, sweep, 60.0 + 40.0 * local.seconds, on_local);
    if (!service) return false;
    services.emplace_back(on_local, std::move(*service));
  }
  const double first_half_s = local.seconds;
  RunInProcess(scenes, scenes.size() / 2, scenes.size(), options.lanes, local);
  const double local_rate = options.sweep_jobs / local.seconds;
  std::printf(
      "in process %.2f s, %.1f jobs/s (one job %.2f ms on its lane; %d failed; half the scenes "
      "before the service ran, in %.2f s, half after, in %.2f s)\n",
      local.seconds, local_rate, local.mean_job_ms, local.failures, first_half_s,
      local.seconds - first_half_s);

  bool met = local.failures == 0;
  for (const auto& [on_local, service] : services) {
    // The limit is on local workers; remote ones alone are judged by it too.
    const bool judged = on_local || options.sweep_on == "remote";
    met = PrintServiceRun(options, service, local, local_rate, on_local, judged) && met;
  }
  std::printf("part 2     %s\n", Verdict(met));
  return met;
}

}  // namespace seep::bench
