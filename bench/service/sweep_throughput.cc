// Part 2 of seep_coordinator_bench: what running a sweep through the service costs against
// running its scenes back to back in process. The same `sweep_jobs` small transients (a lattice
// of sweep_columns x sweep_rows disks, explicit, to sweep_end_time_s; the jobs differ only in
// their inlet pressure, which leaves the work unchanged) run
//   a. in process: `lanes` threads of one core thread each take the scenes in turn and run each
//      as the runner does (DecodeScene, Simulation::Create, Run, Report), and nothing more:
//      no store, no checkpoint, no hash;
//   b. on local workers (--sweep-on local, both or all): one sweep submitted to a seepd with
//      `lanes` workers of its own of one core thread each (--workers N --threads-per-job 1, its
//      default lease and checkpoint settings), each a seep-worker child process (its default
//      --isolation process) with everything a job does there: its claim (with its event) over
//      the data folder's socket, its final checkpoint uploaded, result series and outcome
//      stored;
//   b'. on seepd's threads (--sweep-on threads or all): the same with --isolation thread, each
//      job's end stored in one commit (synced within the store's durability window): (b)'s
//      cost against it is the cost of isolating jobs in processes;
//   c. on remote workers (--sweep-on remote or both): the same sweep on a pure coordinator
//      (seepd --workers 0) drained by `lanes` seep-worker processes on loopback, each with one
//      worker of one core thread, its checkpoint uploaded over gRPC.
// A shared virtual machine's speed drifts by tens of per cent over seconds (seen here: one
// in-process job 11.9 to 16.4 ms from one run to the next, and the two halves of one in-process
// run 15 s apart 28 % apart), more than the service's cost. So (a) and each of (b), (c) take
// turns in slices of `sweep_slice_s`: the service runs a slice (seepd and its workers continued
// with SIGCONT), is stopped (SIGSTOP, mid-job: a stopped process's job just waits), and the
// in-process lanes run a slice; until the sweep is drained and the in-process run has run every
// scene once. Each side is timed over its own slices only: the service's up to the last job's
// finished_at as seepd recorded it (from the sweep's stored, or its first job started if that
// came first; remote: from the workers' launch); the in-process lanes each up to the end of its
// last job of a slice (its idle tail not counted: the in-process rate is its best). All ran the
// same physics: every job's metrics must equal its in-process run's. The whole runs
// `sweep_trials` times (a fresh seepd each). Limit (issue 50: "the 1,000-job sweep still >= 0.85
// of main's in-process throughput" with jobs isolated in processes): the median over the trials
// of (b)'s jobs per second over (a)'s is >= 0.85; (b') and (c)'s medians are printed beside it.
// A stopped seepd's worker processes are stopped with it (they are its children).
#include <fmt/format.h>
#include <google/protobuf/util/time_util.h>
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "codec/scene_codec.h"
#include "coordinator_bench.h"
#include "jobs/wall_clock.h"
#include "seep/core/run/simulation.h"
#include "seep/core/threads.h"
#include "service_bench.h"

namespace seep::bench {
namespace {

using Metrics = std::map<std::string, double>;
using google::protobuf::util::TimeUtil;

struct InProcessRun {
  std::size_t started = 0;       // jobs started so far: job k runs scene k % scenes
  int jobs = 0;                  // jobs run
  double lane_seconds = 0.0;     // summed over lanes and slices, each to its lane's last job end
  double busy_seconds = 0.0;     // summed over jobs: one job's run, set-up included
  std::vector<Metrics> metrics;  // by position, from the first run of each scene
  int failures = 0;
  int slices = 0;

  double Rate(int lanes) const { return jobs / (lane_seconds / lanes); }  // jobs per second
  double MeanJobMs() const { return 1e3 * busy_seconds / jobs; }
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

// One in-process slice: each lane takes the next scene while the slice lasts, so a lane ends
// its slice with the job it started before the slice's end.
void RunInProcessSlice(const std::vector<v1::Scene>& scenes, int lanes, double slice_s,
                       InProcessRun& run) {
  run.metrics.resize(scenes.size());
  std::atomic<std::size_t> next{run.started};
  std::mutex mutex;  // guards run's sums
  const auto start = Clock::now();
  const auto deadline =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(slice_s));
  {
    std::vector<std::jthread> threads;
    for (int lane = 0; lane < lanes; ++lane) {
      threads.emplace_back([&] {
        core::SetCoreThreadsForThisThread(1);  // as seep-worker --threads-per-job 1
        const auto logger = QuietLogger("in-process");
        double busy = 0.0;
        int jobs = 0;
        int failures = 0;
        auto lane_end = start;
        while (Clock::now() < deadline) {
          const std::size_t k = next++;
          const std::size_t i = k % scenes.size();
          const auto job_start = Clock::now();
          auto spec = service::DecodeScene(scenes[i]);
          auto sim = spec.ok() ? core::Simulation::Create(*spec, logger)
                               : core::Result<core::Simulation>(spec.status());
          core::RunControl control;
          control.logger = logger;
          if (!sim.ok() || !sim->Run(control).ok()) {
            ++failures;
          } else if (k < scenes.size()) {  // each position written by one lane only
            for (const auto& [name, value] : sim->Report().metrics) run.metrics[i][name] = value;
          }
          lane_end = Clock::now();
          busy += Seconds(job_start, lane_end);
          ++jobs;
        }
        const std::lock_guard lock(mutex);
        run.lane_seconds += Seconds(start, lane_end);
        run.busy_seconds += busy;
        run.jobs += jobs;
        run.failures += failures;
      });
    }
  }
  run.started = next;
  ++run.slices;
}

struct ServiceRun {
  double submit_s = 0.0;
  double seconds = 0.0;  // its slices, from its start to the last finished_at
  int slices = 0;
  std::vector<v1::SweepJob> jobs;
  bool clean = false;  // seepd and every worker exited 0 on SIGTERM
  // CPU seconds over the drain: where a lane's time went besides the physics.
  double seepd_cpu_s = 0.0;
  double workers_cpu_s = 0.0;
};

// True once no job of the sweep's seepd is QUEUED or RUNNING. Asked once a slice: the drain is
// timed by the jobs' finished_at, not by this poll, and each poll costs seepd about 2 ms of CPU
// while a thousand jobs are queued (a list by state sorts the jobs in those states). (GetSweep
// of every job would cost more still.)
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

// Where the service side of a run runs its jobs.
enum class Side { kLocal, kThreads, kRemote };
constexpr Side kSides[] = {Side::kLocal, Side::kThreads, Side::kRemote};

const char* SideName(Side side) {
  return side == Side::kLocal ? "local" : side == Side::kThreads ? "threads" : "remote";
}

bool SideRuns(const std::string& sweep_on, Side side) {
  if (sweep_on == "all") return true;
  if (sweep_on == "both") return side != Side::kThreads;
  return sweep_on == SideName(side);
}

// Stops (SIGSTOP) or continues (SIGCONT) seepd, its worker processes and the remote workers at
// once.
void SignalAll(Seepd& seepd, const std::vector<ChildProcess>& workers, int signal) {
  ::kill(seepd.process().pid(), signal);
  for (const pid_t child : ChildrenOf(seepd.process().pid())) ::kill(child, signal);
  for (const ChildProcess& worker : workers) ::kill(worker.pid(), signal);
}

// A service slice, in seepd's clock (system milliseconds).
struct Slice {
  std::int64_t start_ms = 0;
  std::int64_t stop_ms = 0;
};

// The time the service ran: its slices, each up to the last job's end.
double ServiceSeconds(const std::vector<Slice>& slices, std::int64_t last_finished_ms) {
  std::int64_t ms = 0;
  for (const Slice& slice : slices) {
    ms += std::clamp(last_finished_ms, slice.start_ms, slice.stop_ms) - slice.start_ms;
  }
  return 1e-3 * static_cast<double>(ms);
}

// local: seepd's own worker processes run the sweep; threads: seepd's threads; remote:
// seep-worker processes on a pure coordinator.
// The service and the in-process lanes (`in_process`) take turns, slice by slice. `trial` names
// its data folder (each trial's seepd starts on an empty one).
std::optional<ServiceRun> RunSliced(const CoordinatorOptions& options, const v1::Sweep& sweep,
                                    const std::vector<v1::Scene>& scenes, Side side, int trial,
                                    InProcessRun& in_process) {
  ServiceRun run;
  const bool local = side != Side::kRemote;
  std::vector<std::string> flags = {"--log-level", "warn"};
  if (local) {
    flags.insert(flags.end(), {"--workers", std::to_string(options.lanes), "--threads-per-job", "1",
                               "--isolation", side == Side::kLocal ? "process" : "thread"});
  }
  Seepd seepd(options, fmt::format("sweep-{}-{}", SideName(side), trial), flags);
  if (seepd.port() <= 0) return std::nullopt;
  auto stub = v1::SeepService::NewStub(seepd.Channel(-1));
  // Local workers start with the submission: their CPU counts from before it.
  const double seepd_cpu_before_submit = seepd.process().CpuSeconds();
  const auto submit_start = Clock::now();
  const std::optional<v1::SweepStatus> submitted = SubmitSweep(*stub, sweep);
  if (!submitted) return std::nullopt;
  run.submit_s = Seconds(submit_start, Clock::now());

  // The system clock, as seepd's timestamps: protobuf's TimeUtil::GetCurrentTime() has whole
  // seconds in Debian's build, which put up to a second of nothing into the service's time.
  std::vector<Slice> slices(1);
  slices.back().start_ms = service::NowMs();
  const double seepd_cpu_start = local ? seepd_cpu_before_submit : seepd.process().CpuSeconds();
  // seepd's worker processes, idle until the submission.
  const std::vector<pid_t> seepd_children = ChildrenOf(seepd.process().pid());
  double children_cpu_start = 0.0;
  for (const pid_t child : seepd_children) children_cpu_start += ProcessCpuSeconds(child);
  std::vector<ChildProcess> workers;
  for (int w = 0; w < (local ? 0 : options.lanes); ++w) {
    workers.emplace_back(
        std::vector<std::string>{options.seep_worker, "--server", seepd.address(), "--workers", "1",
                                 "--threads-per-job", "1", "--log-level", "warn", "--name",
                                 fmt::format("bench-lane-{}", w)},
        options.dir / fmt::format("worker-{}.out", w));
  }
  const auto slice_length = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(options.sweep_slice_s));
  for (auto slice_start = Clock::now();; slice_start = Clock::now()) {
    std::this_thread::sleep_until(slice_start + slice_length);
    const bool drained = Drained(*stub);
    SignalAll(seepd, workers, SIGSTOP);
    slices.back().stop_ms = service::NowMs();
    if (drained) break;
    // Forty times the in-process run's time for the sweep (known after its first slice).
    const double patience_s =
        in_process.jobs == 0 ? 60.0
                             : 60.0 + 40.0 * options.sweep_jobs / in_process.Rate(options.lanes);
    if (1e-3 * static_cast<double>(slices.back().stop_ms - slices.front().start_ms) > patience_s) {
      SignalAll(seepd, workers, SIGCONT);
      std::printf("the workers did not drain the sweep within %.0f s; see %s\n", patience_s,
                  options.dir.c_str());
      return std::nullopt;
    }
    RunInProcessSlice(scenes, options.lanes, options.sweep_slice_s, in_process);
    slices.push_back({service::NowMs(), 0});
    SignalAll(seepd, workers, SIGCONT);
  }
  SignalAll(seepd, workers, SIGCONT);
  // The in-process run goes on alone until it has run every scene once (it is about as fast).
  while (in_process.started < scenes.size()) {
    RunInProcessSlice(scenes, options.lanes, options.sweep_slice_s, in_process);
  }
  run.slices = static_cast<int>(slices.size());
  run.seepd_cpu_s = seepd.process().CpuSeconds() - seepd_cpu_start;
  for (const ChildProcess& worker : workers) run.workers_cpu_s += worker.CpuSeconds();
  for (const pid_t child : seepd_children) run.workers_cpu_s += ProcessCpuSeconds(child);
  run.workers_cpu_s -= children_cpu_start;
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
      slices.front().start_ms = std::min(slices.front().start_ms,
                                         TimeUtil::TimestampToMilliseconds(job.job().started_at()));
    }
  }
  std::int64_t last_ms = slices.front().start_ms;
  for (const v1::SweepJob& job : run.jobs) {
    last_ms = std::max(last_ms, TimeUtil::TimestampToMilliseconds(job.job().finished_at()));
  }
  run.seconds = ServiceSeconds(slices, last_ms);
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

// One service run's figures against its in-process turns; its ratio (service jobs per second
// over in-process ones), or nullopt when its results do not match.
std::optional<double> PrintServiceRun(const CoordinatorOptions& options, const ServiceRun& run,
                                      const InProcessRun& local, Side side) {
  const char* where = SideName(side);
  double claimed_s = 0.0;  // started_at to finished_at, summed (stops included)
  for (const v1::SweepJob& job : run.jobs) {
    claimed_s +=
        1e-3 * static_cast<double>(TimeUtil::TimestampToMilliseconds(job.job().finished_at()) -
                                   TimeUtil::TimestampToMilliseconds(job.job().started_at()));
  }
  const double n = static_cast<double>(options.sweep_jobs);
  const double local_rate = local.Rate(options.lanes);
  std::printf("-- on %s workers (%d %s)\n", where, options.lanes,
              side == Side::kLocal     ? "worker processes of seepd's own"
              : side == Side::kThreads ? "workers on seepd's own threads"
                                       : "seep-worker processes of one worker each");
  std::printf(
      "in process %.2f s of lane time a lane, %.1f jobs/s (%d jobs in %d slices; one job %.2f ms "
      "on its lane; %d failed)\n",
      local.lane_seconds / options.lanes, local_rate, local.jobs, local.slices, local.MeanJobMs(),
      local.failures);
  std::printf(
      "submitted  the sweep in %.2f s (validated and stored in one transaction; not "
      "counted below)\n",
      run.submit_s);
  const double service_rate = n / run.seconds;
  const double lane_ms = 1e3 * run.seconds * options.lanes / n;
  // A worker claims its next job while its last one's end is recorded, so a job's claim to
  // outcome can be longer than its share of a lane.
  std::printf(
      "service    %.2f s in %d slices, %.1f jobs/s; a job takes %.2f ms of a lane; %.2f ms from "
      "its claim to its outcome stored, stops included (its end recorded while the lane runs the "
      "next job)\n",
      run.seconds, run.slices, service_rate, lane_ms, 1e3 * claimed_s / n);
  if (side == Side::kThreads) {
    std::printf(
        "overhead   %.2f ms a job over its in-process run; CPU a job: seepd %.2f ms, its "
        "workers' physics included (the in-process run: %.2f ms of its lane)\n",
        lane_ms - local.MeanJobMs(), 1e3 * run.seepd_cpu_s / n, local.MeanJobMs());
  } else {
    std::printf(
        "overhead   %.2f ms a job over its in-process run; CPU a job: seepd %.2f ms, the "
        "seep-worker processes %.2f ms (the in-process run: %.2f ms of its lane)\n",
        lane_ms - local.MeanJobMs(), 1e3 * run.seepd_cpu_s / n, 1e3 * run.workers_cpu_s / n,
        local.MeanJobMs());
  }
  const int mismatches = Mismatches(run, local);
  std::printf(
      "results    %d of %d jobs SUCCEEDED with their in-process metrics; seepd and "
      "workers stopped with SIGTERM: %s   %s\n",
      options.sweep_jobs - mismatches, options.sweep_jobs, run.clean ? "exit 0" : "NOT clean",
      Verdict(mismatches == 0 && local.failures == 0));
  const double ratio = service_rate / local_rate;
  std::printf("ratio      %s workers / in process = %.3f\n", where, ratio);
  if (mismatches != 0 || local.failures != 0) return std::nullopt;
  return ratio;
}

// "a b c" of the trials' ratios.
std::string Listed(const std::vector<double>& values) {
  std::string out;
  for (const double v : values) out += fmt::format("{}{:.3f}", out.empty() ? "" : " ", v);
  return out;
}

}  // namespace

bool SweepThroughput(const CoordinatorOptions& options) {
  const v1::Scene base =
      TransientLatticeScene(options.sweep_columns, options.sweep_rows, options.sweep_end_time_s);
  const v1::Sweep sweep = InletPressureSweep(base, options.sweep_jobs);
  std::printf(
      "\n== 2. sweep throughput: %d explicit transients on a %u x %u lattice to t = %g s, %d "
      "lane(s) of one core thread, through the service (on %s workers) and in process, taking "
      "turns in slices of %.2f s; %d trial(s), judged by their median ratio\n",
      options.sweep_jobs, options.sweep_columns, options.sweep_rows, options.sweep_end_time_s,
      options.lanes,
      options.sweep_on == "both"  ? "local and remote"
      : options.sweep_on == "all" ? "local, threads and remote"
                                  : options.sweep_on.c_str(),
      options.sweep_slice_s, options.sweep_trials);
  const std::vector<v1::Scene> scenes = ScenesOf(sweep);
  std::map<Side, std::vector<double>> ratios;
  bool met = true;
  for (int trial = 1; trial <= options.sweep_trials; ++trial) {
    std::printf("-- trial %d of %d\n", trial, options.sweep_trials);
    for (const Side side : kSides) {
      if (!SideRuns(options.sweep_on, side)) continue;
      InProcessRun in_process;
      const std::optional<ServiceRun> service =
          RunSliced(options, sweep, scenes, side, trial, in_process);
      const std::optional<double> ratio =
          service ? PrintServiceRun(options, *service, in_process, side) : std::nullopt;
      met = met && ratio.has_value();
      ratios[side].push_back(ratio.value_or(0.0));
    }
  }
  for (const Side side : kSides) {
    const std::vector<double>& list = ratios[side];
    if (list.empty()) continue;
    const char* where = SideName(side);
    const double median = Median(list);
    // The limit is on local workers; any other side run alone is judged by it too.
    const bool judged = side == Side::kLocal || options.sweep_on == SideName(side);
    const bool ratio_met = median >= options.throughput_ratio_limit;
    if (judged) met = met && ratio_met;
    const std::string verdict = judged
                                    ? fmt::format(")   {} (limit: >= {:.2f})", Verdict(ratio_met),
                                                  options.throughput_ratio_limit)
                                    : "; no limit: the issue's is on local workers)";
    std::printf("median     %s workers / in process = %.3f over %zu trial(s) (%s%s\n", where,
                median, list.size(), Listed(list).c_str(), verdict.c_str());
  }
  std::printf("part 2     %s\n", Verdict(met));
  return met;
}

}  // namespace seep::bench
