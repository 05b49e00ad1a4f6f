// SeepServiceImpl: seep.v1.SeepService on gRPC's synchronous API.
//
// Every handler body runs inside Guarded (rpc/handler.h: authentication, no escaping exception).
// Handlers decode, call the store or the hub, encode: they never run physics on their own
// thread. The one that needs physics (GetJobFields) hands it to the PhysicsPool, whose threads
// use a job's thread budget, and waits for it while its call lasts. The synchronous API is
// enough here (a handful of clients, one long stream per watcher); WatchJob waits on the hub
// with a timeout so that cancelled streams and shutdown are noticed within a second.
#pragma once

#include <spdlog/logger.h>

#include <functional>
#include <memory>
#include <string>

#include "jobs/checkpoint_removal.h"
#include "jobs/job_hub.h"
#include "jobs/physics_pool.h"
#include "metrics/service_metrics.h"
#include "rpc/bearer_auth.h"
#include "seep/v1/job_service.grpc.pb.h"
#include "store/job_store.h"

namespace seep::service {

// How the service reaches the worker pool without depending on it.
struct ServiceHooks {
  std::function<void()> wake_workers;                      // a job was queued
  std::function<void(const std::string&)> cancel_running;  // stop this RUNNING job now
};

// Who may call, how big a request and a response may be, how many streams may follow jobs.
// Defaults: no token, 32 MiB scenes, 64 MiB field responses, 100 watch streams.
inline constexpr std::size_t kDefaultMaxSceneBytes = 32u << 20;
inline constexpr std::size_t kDefaultMaxResponseBytes = 64u << 20;
inline constexpr int kDefaultMaxWatchStreams = 100;
struct ServiceGuards {
  const BearerAuth* auth = nullptr;  // null: no token required (owned by the caller)
  std::size_t max_scene_bytes = kDefaultMaxSceneBytes;
  // GetJobFields refuses (RESOURCE_EXHAUSTED, with the size) a response larger than this.
  std::size_t max_response_bytes = kDefaultMaxResponseBytes;
  // WatchJob streams open at once (each holds a server thread); more: RESOURCE_EXHAUSTED.
  int max_watch_streams = kDefaultMaxWatchStreams;
  // A scene whose run is estimated to need more memory than this is refused at submit
  // (RESOURCE_EXHAUSTED, with the figures); 0: no limit.
  std::uint64_t job_memory_limit_bytes = 0;
};

class SeepServiceImpl final : public v1::SeepService::Service {
 public:
  // `physics` runs GetJobFields' physics (owned by the caller, outlives the service).
  // `metrics` (optional, owned by the caller) counts every call by method and code.
  SeepServiceImpl(JobStore& store, JobHub& hub, PhysicsPool& physics, std::string build_id,
                  ServiceHooks hooks, std::shared_ptr<spdlog::logger> logger,
                  ServiceGuards guards = {}, ServiceMetrics* metrics = nullptr);

  // The seep.v1.SeepService calls (job_service.proto says what each does).
  using Ctx = grpc::ServerContext;
  grpc::Status SubmitJob(Ctx*, const v1::SubmitJobRequest*, v1::SubmitJobResponse*) override;
  grpc::Status GetJob(Ctx*, const v1::GetJobRequest*, v1::GetJobResponse*) override;
  grpc::Status ListJobs(Ctx*, const v1::ListJobsRequest*, v1::ListJobsResponse*) override;
  grpc::Status WatchJob(Ctx*, const v1::WatchJobRequest*,
                        grpc::ServerWriter<v1::JobEvent>*) override;
  grpc::Status CancelJob(Ctx*, const v1::CancelJobRequest*, v1::CancelJobResponse*) override;
  grpc::Status ResumeJob(Ctx*, const v1::ResumeJobRequest*, v1::ResumeJobResponse*) override;
  grpc::Status GetResult(Ctx*, const v1::GetResultRequest*, v1::GetResultResponse*) override;
  // seep_service_calibrations.cc
  grpc::Status ListCalibrations(Ctx*, const v1::ListCalibrationsRequest*,
                                v1::ListCalibrationsResponse*) override;
  grpc::Status LookupCalibration(Ctx*, const v1::LookupCalibrationRequest*,
                                 v1::LookupCalibrationResponse*) override;
  // seep_service_fields.cc
  grpc::Status GetJobFields(Ctx*, const v1::GetJobFieldsRequest*,
                            v1::GetJobFieldsResponse*) override;
  // seep_service_operations.cc
  grpc::Status DeleteJob(Ctx*, const v1::DeleteJobRequest*, v1::DeleteJobResponse*) override;
  grpc::Status ListJobEvents(Ctx*, const v1::ListJobEventsRequest*,
                             v1::ListJobEventsResponse*) override;
  // seep_service_sweeps.cc
  grpc::Status SubmitSweep(Ctx*, const v1::SubmitSweepRequest*, v1::SubmitSweepResponse*) override;
  grpc::Status GetSweep(Ctx*, const v1::GetSweepRequest*, v1::GetSweepResponse*) override;
  grpc::Status CancelSweep(Ctx*, const v1::CancelSweepRequest*, v1::CancelSweepResponse*) override;
  grpc::Status ResumeSweep(Ctx*, const v1::ResumeSweepRequest*, v1::ResumeSweepResponse*) override;
  grpc::Status DeleteSweep(Ctx*, const v1::DeleteSweepRequest*, v1::DeleteSweepResponse*) override;

 private:
  // Runs a handler body: rpc/handler.h.
  template <typename Fn>
  grpc::Status Guarded(const grpc::ServerContext* ctx, const char* rpc, Fn&& fn) const;

  // A calibration ready to store: its name and serialized seep.v1.Calibration.
  struct PreparedCalibration {
    std::string name;
    std::string bytes;
  };
  // The calibration half of SubmitJob (seep_service_calibrations.cc). Nothing is stored for a
  // calibration that fails its checks.
  core::Result<PreparedCalibration> PrepareCalibrationJob(const v1::Calibration& calibration);
  // The simulation half: the size limit, full validation, and the serialized scene.
  core::Result<std::string> PrepareSimulationJob(const v1::Scene& scene);
  // The fork half (from_job_id; seep_service_forks.cc), for a fork whose id and serialized
  // scene are set: the parent's checkpoint chosen and verified, the scene compared with the
  // parent's (INVALID_ARGUMENT naming the field), the checkpoint copied for the fork; then the
  // fork and its copy stored together (the copy removed again when they are not).
  struct ForkStart {
    std::string parent_job_id;
    CheckpointRecord checkpoint;  // the copy, written
  };
  core::Result<ForkStart> PrepareFork(const v1::SubmitJobRequest& request, const JobRecord& fork);
  core::Result<InsertOutcome> InsertFork(const v1::SubmitJobRequest& request, JobRecord& fork);
  // Removes a fork's copy of its parent's checkpoint and the folder it made for it.
  void RemoveForkCopy(const std::filesystem::path& path);

  // What CancelJob, ResumeJob and DeleteJob do to one job, shared with the sweep calls: the
  // store's change, the log line, and the hub and workers told. Delete removes the files of the
  // records the store returned.
  core::Result<JobRecord> CancelOne(const std::string& id);
  core::Result<JobRecord> ResumeOne(const std::string& id);
  RemovedFiles FinishDeletion(const std::vector<std::string>& job_ids,
                              const std::vector<CheckpointRecord>& records);

  // The sweep with its jobs as they are now (seep_service_sweeps.cc), and its definition as
  // submitted when definition_out is given.
  core::Status FillSweepStatus(const SweepRecord& record, v1::SweepStatus* out,
                               v1::Sweep* definition_out = nullptr);
  // Every point of a submitted sweep as a job ready to store, or the point's error.
  core::Result<std::vector<JobRecord>> SweepJobs(const v1::SubmitSweepRequest& request,
                                                 const std::string& sweep_id);

  // WatchJob's stream of one job, until it is terminal, the call ends or seepd shuts down.
  core::Status StreamJob(grpc::ServerContext& ctx, const std::string& id,
                         const JobHub::Follower& follower,
                         grpc::ServerWriter<v1::JobEvent>& writer);

  // The stored job with the hub's live progress laid over it.
  core::Result<JobRecord> LoadJob(const std::string& id, bool with_scene = true);

  JobStore& store_;
  JobHub& hub_;
  PhysicsPool& physics_;
  std::string build_id_;
  ServiceHooks hooks_;
  std::shared_ptr<spdlog::logger> logger_;
  ServiceGuards guards_;
  ServiceMetrics* metrics_;
};

}  // namespace seep::service
