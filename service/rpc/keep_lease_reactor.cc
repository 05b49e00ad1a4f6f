#include "rpc/keep_lease_reactor.h"

#include <fmt/format.h>

#include <exception>
#include <utility>

#include "rpc/status_mapping.h"

namespace seep::service {

KeepLeaseReactor::KeepLeaseReactor(grpc::CallbackServerContext* ctx, const BearerAuth* auth,
                                   LeaseBeatHandler beat, spdlog::logger& logger,
                                   ServiceMetrics* metrics)
    : beat_handler_(std::move(beat)), logger_(logger), metrics_(metrics) {
  if (auth != nullptr) {
    if (grpc::Status denied = auth->CheckMetadata(ctx->client_metadata()); !denied.ok()) {
      logger_.warn("KeepLease from {}: refused: {}", ctx->peer(), denied.error_message());
      End(denied);
      return;
    }
  }
  StartRead(&beat_);
}

void KeepLeaseReactor::OnReadDone(bool ok) {
  if (!ok) {  // the worker's WritesDone, or the stream broke
    End(grpc::Status::OK);
    return;
  }
  if (!lease_) {
    lease_ = beat_.lease();
  } else if (beat_.lease().job_id() != lease_->job_id() ||
             beat_.lease().lease_epoch() != lease_->lease_epoch()) {
    End(ToGrpcStatus(core::InvalidArgument(fmt::format(
        "lease: every beat of a KeepLease stream names the lease of its first (job {}, epoch {}); "
        "got job {}, epoch {}",
        lease_->job_id(), lease_->lease_epoch(), beat_.lease().job_id(),
        beat_.lease().lease_epoch()))));
    return;
  }
  core::Result<bool> cancel = core::Internal("KeepLease: internal error");
  try {
    cancel = beat_handler_(beat_);
  } catch (const std::exception& e) {
    logger_.error("KeepLease: unexpected exception: {}", e.what());
  }
  if (!cancel.ok()) {
    End(ToGrpcStatus(cancel.status()));
    return;
  }
  if (*cancel && !told_cancel_) {
    told_cancel_ = true;
    news_.set_cancel_requested(true);
    StartWrite(&news_);  // the next read starts once it is written
    return;
  }
  StartRead(&beat_);
}

void KeepLeaseReactor::OnWriteDone(bool ok) {
  if (!ok) {
    End(grpc::Status(grpc::StatusCode::UNAVAILABLE, "KeepLease: the stream broke"));
    return;
  }
  StartRead(&beat_);
}

void KeepLeaseReactor::End(const grpc::Status& status) {
  if (metrics_ != nullptr) metrics_->CountRpc("KeepLease", GrpcCodeName(status.error_code()));
  Finish(status);
}

}  // namespace seep::service
