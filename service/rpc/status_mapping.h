// The one place core::Status becomes grpc::Status.
#pragma once

#include <grpcpp/support/status.h>

#include "seep/core/status.h"

namespace seep::service {

grpc::Status ToGrpcStatus(const core::Status& status);
// The canonical name of a gRPC code ("OK", "NOT_FOUND", ...), for logs and metrics labels.
const char* GrpcCodeName(grpc::StatusCode code);

}  // namespace seep::service
