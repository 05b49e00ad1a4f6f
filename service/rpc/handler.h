// What every SeepService handler shares (seep_service*.cc): the wrapper its body runs in, and
// the paging arguments of the list calls.
#pragma once

#include <fmt/format.h>

#include <cstdint>
#include <string>
#include <utility>

#include "rpc/guarded_call.h"
#include "rpc/request_bounds.h"
#include "rpc/seep_service.h"

namespace seep::service {

// GuardedCall (rpc/guarded_call.h) with this service's token, log and metrics.
template <typename Fn>
grpc::Status SeepServiceImpl::Guarded(const grpc::ServerContext* ctx, const char* rpc,
                                      Fn&& fn) const {
  return GuardedCall(guards_.auth, *logger_, metrics_, ctx, rpc, std::forward<Fn>(fn));
}

// INVALID_ARGUMENT "<field>: is required" for an empty id, and for one past kMaxIdLength.
inline core::Status RequireId(const std::string& id, const char* field) {
  if (id.empty()) return core::InvalidArgument(fmt::format("{}: is required", field));
  return CheckIdLength(id, field);
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
