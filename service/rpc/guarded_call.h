// GuardedCall: the one wrapper every gRPC handler body of seepd runs in (SeepService and
// WorkerService alike). The caller is authenticated first (when seepd has a token; a refusal is
// logged), and no exception escapes into gRPC: it is logged and the caller gets INTERNAL
// "<rpc>: internal error". Every outcome is counted by method and code (ServiceMetrics), when
// seepd keeps metrics. The body returns a grpc::Status or a core::Status (mapped by ToGrpcStatus).
#pragma once

#include <fmt/format.h>
#include <grpcpp/grpcpp.h>
#include <spdlog/logger.h>

#include <exception>
#include <type_traits>

#include "metrics/service_metrics.h"
#include "rpc/bearer_auth.h"
#include "rpc/status_mapping.h"

namespace seep::service {

template <typename Fn>
grpc::Status GuardedCall(const BearerAuth* auth, spdlog::logger& logger, ServiceMetrics* metrics,
                         const grpc::ServerContext* ctx, const char* rpc, Fn&& fn) {
  const auto counted = [&](grpc::Status status) {
    if (metrics != nullptr) metrics->CountRpc(rpc, GrpcCodeName(status.error_code()));
    return status;
  };
  if (auth != nullptr) {
    if (grpc::Status denied = auth->Check(*ctx); !denied.ok()) {
      logger.warn("{} from {}: refused: {}", rpc, ctx->peer(), denied.error_message());
      return counted(denied);
    }
  }
  try {
    if constexpr (std::is_same_v<std::invoke_result_t<Fn>, core::Status>) {
      return counted(ToGrpcStatus(fn()));
    } else {
      return counted(fn());
    }
  } catch (const std::exception& e) {
    logger.error("{}: unexpected exception: {}", rpc, e.what());
    return counted({grpc::StatusCode::INTERNAL, fmt::format("{}: internal error", rpc)});
  }
}

}  // namespace seep::service
