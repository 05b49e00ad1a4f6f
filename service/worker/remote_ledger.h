// RemoteLedger: the JobLedger of a remote worker (seep-worker), each call one WorkerService RPC
// to the coordinating seepd (proto/seep/v1/worker_service.proto), but for the heartbeats and
// progress of a running job: those are beats of the job's one KeepLease stream (LeaseStream),
// opened at its first beat and closed before the job is finished or given back. Checkpoints go up
// in chunks of at most 1 MiB with their size and SHA-256 and come down the same way, verified
// before use; the worker keeps nothing on its own disk.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "jobs/job_ledger.h"
#include "seep/v1/worker_service.grpc.pb.h"
#include "worker/lease_stream.h"

namespace seep::service {

class RemoteLedger final : public JobLedger {
 public:
  // `prepare` sets what every call carries (the bearer token); `timeout` bounds each unary call
  // (a checkpoint transfer gets ten times as long); `placement`: the batch job and node this
  // worker runs in, said in every claim (none: outside a batch system).
  RemoteLedger(const std::shared_ptr<grpc::Channel>& channel,
               std::function<void(grpc::ClientContext*)> prepare, std::chrono::milliseconds timeout,
               std::optional<WorkerPlacement> placement = std::nullopt);

  core::Result<std::optional<JobRecord>> Claim(const std::string& owner,
                                               std::chrono::milliseconds lease) override;
  core::Result<bool> Heartbeat(const std::string& id, std::int64_t epoch,
                               std::chrono::milliseconds lease) override;
  core::Status UpdateProgress(const std::string& id, std::int64_t epoch,
                              const JobProgress& progress) override;
  core::Status AddEvent(const std::string& id, std::int64_t epoch, const std::string& kind,
                        const std::string& message) override;
  core::Result<std::int64_t> SaveCheckpoint(const JobRecord& job, const CheckpointMeta& meta,
                                            std::string_view state, std::uint32_t keep,
                                            CheckpointRole role) override;
  core::Result<std::optional<FetchedCheckpoint>> NewestCheckpoint(
      const JobRecord& job, std::optional<std::uint64_t> below_step) override;
  core::Status StoreResultSeries(const std::string& id, std::int64_t epoch,
                                 const std::vector<std::string>& columns,
                                 const std::vector<double>& values, const std::string& state_sha256,
                                 const JobProgress& final_progress) override;
  core::Status Finish(const std::string& id, std::int64_t epoch, JobState state,
                      const std::string& error_code, const std::string& error_message,
                      const std::vector<std::pair<std::string, double>>& metrics,
                      double wall_time_s) override;
  core::Status ReleaseLease(const std::string& id, std::int64_t epoch) override;

 private:
  // A context with the token and a deadline of `timeout` from now.
  std::unique_ptr<grpc::ClientContext> Context(std::chrono::milliseconds timeout) const;
  // A beat on the job's stream (opened when it has none under `epoch`); a stream that ended is
  // dropped after saying why, and the next beat opens a new one.
  core::Result<bool> Beat(const std::string& id, std::int64_t epoch,
                          std::chrono::milliseconds lease, const v1::Progress* progress);
  // Ends the job's stream, if it has one (its beats are then all handled by seepd), for good.
  void CloseStream(const std::string& id, std::int64_t epoch);

  std::unique_ptr<v1::WorkerService::Stub> stub_;
  std::function<void(grpc::ClientContext*)> prepare_;
  std::chrono::milliseconds timeout_;
  std::optional<WorkerPlacement> placement_;
  std::mutex streams_mutex_;
  std::map<std::string, std::shared_ptr<LeaseStream>> streams_;  // by job id
  // The leases whose stream was closed for the job's end: a heartbeat racing the end (the runner
  // stops beating a job only after finishing it) gets ABORTED instead of opening a new stream.
  // Forgotten wholesale past kClosedLeasesKept entries: that race lasts a heartbeat, not a job.
  std::map<std::string, std::int64_t> closed_epochs_;
};

// A gRPC status as the runner reads it: the codes core knows keep their meaning (ABORTED: the
// lease is lost; UNAVAILABLE: try again), DEADLINE_EXCEEDED counts as UNAVAILABLE, the others
// become INTERNAL; the message starts with the call and the gRPC code's name.
core::Status FromGrpcStatus(const char* rpc, const grpc::Status& status);

}  // namespace seep::service
