#include "rpc/undecodable_request.h"

#include <fmt/format.h>
#include <google/protobuf/descriptor.h>
#include <grpcpp/support/interceptor.h>

#include <string>

namespace seep::service {
namespace {

using grpc::experimental::InterceptionHookPoints;

// "/seep.v1.SeepService/GetJob" -> the method's request type, from the generated descriptors.
std::string RequestTypeOf(const std::string& method) {
  const auto slash = method.rfind('/');
  if (method.empty() || slash == std::string::npos || slash == 0) return "its request message";
  const std::string full = method.substr(1, slash - 1) + "." + method.substr(slash + 1);
  const auto* descriptor =
      google::protobuf::DescriptorPool::generated_pool()->FindMethodByName(full);
  return descriptor != nullptr ? descriptor->input_type()->full_name() : "its request message";
}

class UndecodableRequestInterceptor : public grpc::experimental::Interceptor {
 public:
  explicit UndecodableRequestInterceptor(std::string method) : method_(std::move(method)) {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    // A failed decode leaves no message behind it.
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::POST_RECV_MESSAGE) &&
        methods->GetRecvMessage() == nullptr) {
      undecodable_ = true;
    }
    if (undecodable_ &&
        methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS)) {
      const auto slash = method_.rfind('/');
      methods->ModifySendStatus(grpc::Status(
          grpc::StatusCode::INVALID_ARGUMENT,
          fmt::format("{}: the request's bytes do not decode as {} (not that message's protobuf "
                      "wire format)",
                      slash == std::string::npos ? method_ : method_.substr(slash + 1),
                      RequestTypeOf(method_))));
    }
    methods->Proceed();
  }

 private:
  std::string method_;
  bool undecodable_ = false;
};

}  // namespace

grpc::experimental::Interceptor* UndecodableRequestInterceptorFactory::CreateServerInterceptor(
    grpc::experimental::ServerRpcInfo* info) {
  using Type = grpc::experimental::ServerRpcInfo::Type;
  if (info->type() != Type::UNARY && info->type() != Type::SERVER_STREAMING) return nullptr;
  return new UndecodableRequestInterceptor(info->method() != nullptr ? info->method() : "");
}

}  // namespace seep::service
