// What every command file shares with commands.cc: the channel, the per-call deadline and token,
// the exit code of a failed call, JSON printing and request ids.
#pragma once

#include <google/protobuf/message.h>
#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>

#include "commands.h"

namespace seep::client {

// The exit code of a command refused before any call (a bad argument or file): what the server
// itself answers for bad input, INVALID_ARGUMENT.
inline constexpr int kBadInput = static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT);

std::shared_ptr<grpc::Channel> OpenChannel(const GlobalOptions& global);
// Deadline (--timeout) and bearer token: what every unary call needs.
void PrepareUnaryCall(const GlobalOptions& global, grpc::ClientContext* ctx);
// Prints what failed and returns the exit code (the gRPC status code; 14 when unreachable).
int ReportCallError(const GlobalOptions& global, const char* what, const grpc::Status& status);
std::string MessageToJson(const google::protobuf::Message& message);
std::string NewSubmitRequestId();
// Width of the terminal on stdout; 80 when it cannot be told.
int StdoutColumns();

}  // namespace seep::client
