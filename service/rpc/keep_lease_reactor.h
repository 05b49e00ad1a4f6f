// KeepLeaseReactor: one WorkerService.KeepLease stream on seepd's side (gRPC's callback API, so
// that a hundred workers' open streams hold no thread of seepd between their beats). Each beat is
// handed to `beat` (the fenced heartbeat and progress writes of WorkerServiceImpl::Beat) on
// gRPC's thread as it arrives, in order; the answer is news only: one LeaseNews when `beat` first
// says a cancel is pending. A refused beat ends the stream with its status; the worker's
// WritesDone ends it OK; a beat naming another lease than the first ends it INVALID_ARGUMENT. The
// caller is authenticated once, when the stream opens.
#pragma once

#include <grpcpp/grpcpp.h>
#include <spdlog/logger.h>

#include <functional>
#include <optional>

#include "metrics/service_metrics.h"
#include "rpc/bearer_auth.h"
#include "seep/core/status.h"
#include "seep/v1/worker_service.grpc.pb.h"

namespace seep::service {

// What a beat did: true when a cancel of the job is pending.
using LeaseBeatHandler = std::function<core::Result<bool>(const v1::LeaseBeat&)>;

class KeepLeaseReactor final : public grpc::ServerBidiReactor<v1::LeaseBeat, v1::LeaseNews> {
 public:
  // Deletes itself when gRPC is done with the stream (OnDone).
  KeepLeaseReactor(grpc::CallbackServerContext* ctx, const BearerAuth* auth, LeaseBeatHandler beat,
                   spdlog::logger& logger, ServiceMetrics* metrics);

  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnDone() override { delete this; }

 private:
  void End(const grpc::Status& status);

  LeaseBeatHandler beat_handler_;
  spdlog::logger& logger_;
  ServiceMetrics* metrics_;
  v1::LeaseBeat beat_;
  std::optional<v1::LeaseRef> lease_;  // of the first beat: every later one must name it too
  v1::LeaseNews news_;
  bool told_cancel_ = false;
};

}  // namespace seep::service
