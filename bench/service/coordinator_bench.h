// What the two parts of seep_coordinator_bench (issue 18) share: their options, a seepd started
// as a child process on a scratch folder, and the sweep submission both parts queue their jobs
// with. Each part prints its figures, its limit and PASS/MISS, and returns whether it was met.
#pragma once

#include <grpcpp/grpcpp.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "child_process.h"
#include "seep/v1/job_service.grpc.pb.h"

namespace seep::bench {

struct CoordinatorOptions {
  std::string seepd = SEEPD_PATH;
  std::string seep_worker = SEEP_WORKER_PATH;
  std::filesystem::path dir;  // scratch (a real disk: every store commit is an fsync)

  // 1. Coordinator load.
  int queued_jobs = 10'000;
  int simulated_workers = 100;
  double heartbeat_s = 1.0;     // between two heartbeats of a simulated worker's job
  int heartbeats_per_job = 60;  // then it finishes the job and claims the next (1-minute jobs)
  double warmup_s = 5.0;        // before the measured window: every worker holds a job
  double load_seconds = 30.0;   // the measured window
  double floor_seconds = 10.0;  // then the same call rate of trivial calls (0: skipped)
  double cpu_limit_percent = 5.0;
  double lease_p99_limit_ms = 20.0;

  // 2. Sweep throughput.
  int sweep_jobs = 1000;
  int lanes = 2;  // seep-worker processes of one worker each; as many in-process lanes
  // Where the service runs the sweep: "local" (seepd's own workers, `lanes` of them: the issue's
  // "local workers"), "remote" (a pure coordinator and `lanes` seep-worker processes), or "both".
  std::string sweep_on = "both";
  std::uint32_t sweep_columns = 40;
  std::uint32_t sweep_rows = 40;
  double sweep_end_time_s = 3.1484e-3;  // about 1,500 explicit steps
  // On the median of the trials' ratios (issue 50: jobs isolated in worker processes).
  double throughput_ratio_limit = 0.85;
  int sweep_trials = 5;
  double sweep_slice_s = 1.0;  // the service and the in-process run take turns

  bool keep = false;  // keep the scratch folder
};

// A seepd on loopback with its data folder in dir/<name>, its port file and output beside it.
class Seepd {
 public:
  // Starts `seepd --workers 0 ... extra`; check port() > 0.
  Seepd(const CoordinatorOptions& options, const std::string& name,
        const std::vector<std::string>& extra);
  int port() const { return port_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  ChildProcess& process() { return process_; }
  const std::filesystem::path& output() const { return output_; }
  // A channel of its own (not shared with other channels of this process: `tag` tells them
  // apart), taking replies as large as a 10,000-job sweep's.
  std::shared_ptr<grpc::Channel> Channel(int tag) const;
  // SIGTERM, then true when it exited with status 0.
  bool Stop();

 private:
  std::filesystem::path output_;
  ChildProcess process_;
  int port_ = -1;
};

// A sweep of `jobs` copies of `base` that differ only in boundary.inlet_pressure_pa (which leaves
// the work of a rigid lattice's run unchanged), at most 10,000 (the service's limit).
v1::Sweep InletPressureSweep(const v1::Scene& base, int jobs);
// SubmitSweep; nullopt (after printing why) when the call fails.
std::optional<v1::SweepStatus> SubmitSweep(v1::SeepService::Stub& stub, const v1::Sweep& sweep);

// seepd's CPU (% of one core) while `clients` threads call grpc.health.v1.Health/Check at
// calls_per_second in all for `seconds`: the cost of gRPC alone at that rate (call_floor.cc).
double TrivialCallCpuPercent(Seepd& seepd, int clients, double calls_per_second, double seconds);

bool CoordinatorLoad(const CoordinatorOptions& options);
bool SweepThroughput(const CoordinatorOptions& options);

}  // namespace seep::bench
