// WorkerServiceImpl: seep.v1.WorkerService (proto/seep/v1/worker_service.proto), the calls of
// remote workers (seep-worker). Thin: each call checks its request (INVALID_ARGUMENT naming the
// field), finds the job (NOT_FOUND), checks the lease (ABORTED for a stale epoch) and hands the
// write to seepd's StoreLedger, whose store writes are fenced by the epoch once more; progress
// and outcomes also reach the JobHub, so WatchJob follows a remote job as a local one.
#pragma once

#include <spdlog/logger.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "jobs/job_hub.h"
#include "jobs/store_ledger.h"
#include "metrics/service_metrics.h"
#include "rpc/bearer_auth.h"
#include "seep/v1/worker_service.grpc.pb.h"
#include "store/job_store.h"

namespace seep::service {

// The default of seepd --max-checkpoint-bytes: what protobuf can serialize in one message, the
// most a state can be anyway (state_size_estimate refuses larger scenes at submit).
inline constexpr std::uint64_t kDefaultMaxCheckpointUploadBytes = 2147483647;

struct WorkerServiceOptions {
  const BearerAuth* auth = nullptr;  // null: no token required (owned by the caller)
  // An upload whose declared state is larger fails RESOURCE_EXHAUSTED before any byte is kept.
  std::uint64_t max_checkpoint_bytes = kDefaultMaxCheckpointUploadBytes;
};

// KeepLease runs on gRPC's callback API (KeepLeaseReactor), the other methods synchronously.
class WorkerServiceImpl final
    : public v1::WorkerService::WithCallbackMethod_KeepLease<v1::WorkerService::Service> {
 public:
  WorkerServiceImpl(JobStore& store, StoreLedger& ledger, JobHub& hub,
                    std::shared_ptr<spdlog::logger> logger, WorkerServiceOptions options = {},
                    ServiceMetrics* metrics = nullptr);

  using Ctx = grpc::ServerContext;
  grpc::Status ClaimJob(Ctx*, const v1::ClaimJobRequest*, v1::ClaimJobResponse*) override;
  grpc::Status Heartbeat(Ctx*, const v1::HeartbeatRequest*, v1::HeartbeatResponse*) override;
  grpc::Status ReportProgress(Ctx*, const v1::ReportProgressRequest*,
                              v1::ReportProgressResponse*) override;
  grpc::ServerBidiReactor<v1::LeaseBeat, v1::LeaseNews>* KeepLease(
      grpc::CallbackServerContext* ctx) override;
  grpc::Status AddJobEvent(Ctx*, const v1::AddJobEventRequest*, v1::AddJobEventResponse*) override;
  grpc::Status UploadCheckpoint(Ctx*, grpc::ServerReader<v1::UploadCheckpointRequest>*,
                                v1::UploadCheckpointResponse*) override;
  grpc::Status DownloadCheckpoint(Ctx*, const v1::DownloadCheckpointRequest*,
                                  grpc::ServerWriter<v1::DownloadCheckpointResponse>*) override;
  grpc::Status StoreResultSeries(Ctx*, const v1::StoreResultSeriesRequest*,
                                 v1::StoreResultSeriesResponse*) override;
  grpc::Status FinishJob(Ctx*, const v1::FinishJobRequest*, v1::FinishJobResponse*) override;
  grpc::Status ReturnJob(Ctx*, const v1::ReturnJobRequest*, v1::ReturnJobResponse*) override;

 private:
  template <typename Fn>
  grpc::Status Guarded(const grpc::ServerContext* ctx, const char* rpc, Fn&& fn) const;
  // The job a lease names, when it is RUNNING under that epoch: INVALID_ARGUMENT for a missing
  // field (named `field`.job_id / .lease_epoch), NOT_FOUND for an unknown job, ABORTED when the
  // lease was taken over or the job is no longer RUNNING. with_scene: also its scene bytes.
  core::Result<JobRecord> HeldJob(const v1::LeaseRef& lease, const char* field, bool with_scene);
  // The fenced write `write` for the lease (its fields checked first, as HeldJob does); when the
  // store refuses it (ABORTED), HeldJob's reading of the job says why. The job is read only then:
  // the fenced write alone keeps a stale worker out, and the calls a worker makes every second
  // (heartbeats, progress) cost one statement instead of that and five reads of the job.
  core::Status FencedWrite(const v1::LeaseRef& lease, const char* field,
                           const std::function<core::Status()>& write);
  // A renewal of the lease by lease_ms (Heartbeat, and a beat): true when a cancel is pending.
  core::Result<bool> Renew(const v1::LeaseRef& lease, std::uint32_t lease_ms);
  // The job's live progress stored and published to its followers (ReportProgress, and a beat).
  core::Status StoreProgress(const v1::LeaseRef& lease, const v1::Progress& progress);
  // One beat of a KeepLease stream: Renew, then StoreProgress when the beat carries progress.
  // True when a cancel of the job is pending.
  core::Result<bool> Beat(const v1::LeaseBeat& beat);
  // The checkpoint upload after its first message: chunks read, checked and kept.
  grpc::Status ReceiveCheckpoint(grpc::ServerReader<v1::UploadCheckpointRequest>& reader,
                                 const v1::CheckpointUploadStart& start,
                                 v1::UploadCheckpointResponse* response);

  // Counts into metrics_ the steps a job made since the step last counted for it (its claim's
  // stored progress at first): the steps of jobs in worker processes, from their progress.
  void CountSteps(const std::string& id, std::uint64_t step);

  JobStore& store_;
  StoreLedger& ledger_;
  JobHub& hub_;
  std::shared_ptr<spdlog::logger> logger_;
  WorkerServiceOptions options_;
  ServiceMetrics* metrics_;
  std::mutex counted_mutex_;
  std::map<std::string, std::uint64_t> counted_steps_;  // job id -> step counted up to
};

}  // namespace seep::service
