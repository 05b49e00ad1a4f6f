// SeepServiceImpl: seep.v1.SeepService on gRPC's synchronous API.
//
// Handlers decode, call the store or the hub, encode: they never run physics. The synchronous
// API is enough here (a handful of clients, one long stream per watcher); WatchJob waits on the
// hub with a timeout so that cancelled streams and shutdown are noticed within a second.
#pragma once

#include <spdlog/logger.h>

#include <functional>
#include <memory>
#include <string>

#include "jobs/job_hub.h"
#include "rpc/bearer_auth.h"
#include "seep/v1/job_service.grpc.pb.h"
#include "store/job_store.h"

namespace seep::service {

// How the service reaches the worker pool without depending on it.
struct ServiceHooks {
  std::function<void()> wake_workers;                      // a job was queued
  std::function<void(const std::string&)> cancel_running;  // stop this RUNNING job now
};

// Who may call and how big a request may be. Defaults: no token, 32 MiB scenes.
inline constexpr std::size_t kDefaultMaxSceneBytes = 32u << 20;
struct ServiceGuards {
  const BearerAuth* auth = nullptr;  // null: no token required (owned by the caller)
  std::size_t max_scene_bytes = kDefaultMaxSceneBytes;
};

class SeepServiceImpl final : public v1::SeepService::Service {
 public:
  SeepServiceImpl(JobStore& store, JobHub& hub, std::string build_id, ServiceHooks hooks,
                  std::shared_ptr<spdlog::logger> logger, ServiceGuards guards = {});

  grpc::Status SubmitJob(grpc::ServerContext* ctx, const v1::SubmitJobRequest* req,
                         v1::SubmitJobResponse* resp) override;
  grpc::Status GetJob(grpc::ServerContext* ctx, const v1::GetJobRequest* req,
                      v1::GetJobResponse* resp) override;
  grpc::Status ListJobs(grpc::ServerContext* ctx, const v1::ListJobsRequest* req,
                        v1::ListJobsResponse* resp) override;
  grpc::Status WatchJob(grpc::ServerContext* ctx, const v1::WatchJobRequest* req,
                        grpc::ServerWriter<v1::JobEvent>* writer) override;
  grpc::Status CancelJob(grpc::ServerContext* ctx, const v1::CancelJobRequest* req,
                         v1::CancelJobResponse* resp) override;
  grpc::Status ResumeJob(grpc::ServerContext* ctx, const v1::ResumeJobRequest* req,
                         v1::ResumeJobResponse* resp) override;
  grpc::Status GetResult(grpc::ServerContext* ctx, const v1::GetResultRequest* req,
                         v1::GetResultResponse* resp) override;
  grpc::Status ListCalibrations(grpc::ServerContext* ctx, const v1::ListCalibrationsRequest* req,
                                v1::ListCalibrationsResponse* resp) override;
  grpc::Status LookupCalibration(grpc::ServerContext* ctx, const v1::LookupCalibrationRequest* req,
                                 v1::LookupCalibrationResponse* resp) override;
  // seep_service_fields.cc
  grpc::Status GetJobFields(grpc::ServerContext* ctx, const v1::GetJobFieldsRequest* req,
                            v1::GetJobFieldsResponse* resp) override;

 private:
  // A calibration ready to store: its name and serialized seep.v1.Calibration.
  struct PreparedCalibration {
    std::string name;
    std::string bytes;
  };
  // The calibration half of SubmitJob and the calibration queries
  // (seep_service_calibrations.cc). Nothing is stored for a calibration that fails its checks.
  core::Result<PreparedCalibration> PrepareCalibrationJob(const v1::Calibration& calibration);
  grpc::Status DoListCalibrations(const v1::ListCalibrationsRequest& req,
                                  v1::ListCalibrationsResponse* resp);
  grpc::Status DoLookupCalibration(const v1::LookupCalibrationRequest& req,
                                   v1::LookupCalibrationResponse* resp);

  // The stored job with the hub's live progress laid over it.
  core::Result<JobRecord> LoadJob(const std::string& id);

  JobStore& store_;
  JobHub& hub_;
  std::string build_id_;
  ServiceHooks hooks_;
  std::shared_ptr<spdlog::logger> logger_;
  ServiceGuards guards_;
};

}  // namespace seep::service
