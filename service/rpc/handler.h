// What every SeepService handler shares (seep_service*.cc): the wrapper its body runs in, and
// the paging arguments of the list calls.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <exception>
#include <string>
#include <type_traits>

#include "rpc/seep_service.h"
#include "rpc/status_mapping.h"

namespace seep::service {

// The caller is authenticated first (when seepd has a token; a refusal is logged), and no
// exception escapes into gRPC: it is logged and the caller gets INTERNAL "<rpc>: internal error".
// Every outcome is counted by method and code (ServiceMetrics), when seepd keeps metrics.
// The body returns a grpc::Status or a core::Status (mapped by ToGrpcStatus).
template <typename Fn>
grpc::Status SeepServiceImpl::Guarded(const grpc::ServerContext* ctx, const char* rpc,
                                      Fn&& fn) const {
  const auto counted = [&](grpc::Status status) {
    if (metrics_ != nullptr) metrics_->CountRpc(rpc, GrpcCodeName(status.error_code()));
    return status;
  };
  if (guards_.auth != nullptr) {
    if (grpc::Status denied = guards_.auth->Check(*ctx); !denied.ok()) {
      logger_->warn("{} from {}: refused: {}", rpc, ctx->peer(), denied.error_message());
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
    logger_->error("{}: unexpected exception: {}", rpc, e.what());
    return counted({grpc::StatusCode::INTERNAL, fmt::format("{}: internal error", rpc)});
  }
}

// INVALID_ARGUMENT "<field>: is required" for an empty id.
inline core::Status RequireId(const std::string& id, const char* field) {
  if (!id.empty()) return core::Status::Ok();
  return core::InvalidArgument(fmt::format("{}: is required", field));
}

// SubmitJobRequest and SubmitSweepRequest share these checks: INVALID_ARGUMENT naming the field.
core::Status CheckRequestId(const std::string& request_id);
core::Status CheckPriority(std::int32_t priority);
// A new random id with the kind's prefix ("j" for jobs, "s" for sweeps): see seep_service.cc.
core::Result<std::string> NewRandomId(char prefix);

// A list call's page size: 0 asks for the default (50), and at most 1000 are returned.
inline std::uint32_t PageSize(std::uint32_t requested) {
  constexpr std::uint32_t kDefault = 50;
  constexpr std::uint32_t kMax = 1000;
  return requested == 0 ? kDefault : std::min(requested, kMax);
}

}  // namespace seep::service
