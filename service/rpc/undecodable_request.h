// A request whose bytes do not decode as its method's message: gRPC answers it before any handler
// runs, with INTERNAL and an empty message. This server interceptor turns that answer into
// INVALID_ARGUMENT saying what could not be decoded ("GetJob: the request's bytes do not decode as
// seep.v1.GetJobRequest ...").
#pragma once

#include <grpcpp/support/server_interceptor.h>

namespace seep::service {

// For seepd's ServerBuilder (experimental().SetInterceptorCreators). Unary and server-streaming
// calls only: their one request is decoded before the handler; a stream's reads end without a
// message, which is no failure.
class UndecodableRequestInterceptorFactory
    : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override;
};

}  // namespace seep::service
