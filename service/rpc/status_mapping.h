// The one place core::Status becomes grpc::Status.
#pragma once

#include <grpcpp/support/status.h>

#include "seep/core/status.h"

namespace seep::service {

grpc::Status ToGrpcStatus(const core::Status& status);

}  // namespace seep::service
