#include "job_admin_commands.h"

#include <fmt/format.h>
#include <grpcpp/grpcpp.h>

#include <iostream>

#include "call_support.h"
#include "job_printer.h"
#include "seep/v1/job_service.grpc.pb.h"

namespace seep::client {

std::string ParseLabelOptions(const std::vector<std::string>& options,
                              google::protobuf::Map<std::string, std::string>* out) {
  for (const std::string& option : options) {
    const auto equals = option.find('=');
    if (equals == std::string::npos || equals == 0) {
      return fmt::format("--label {}: expected KEY=VALUE", option);
    }
    const std::string key = option.substr(0, equals);
    if (!out->insert({key, option.substr(equals + 1)}).second) {
      return fmt::format("--label {}: the key '{}' is given twice", option, key);
    }
  }
  return {};
}

int Delete(const GlobalOptions& global, const std::string& job_id) {
  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  grpc::ClientContext ctx;
  PrepareUnaryCall(global, &ctx);
  v1::DeleteJobRequest request;
  request.set_id(job_id);
  v1::DeleteJobResponse response;
  if (auto status = stub->DeleteJob(&ctx, request, &response); !status.ok()) {
    return ReportCallError(global, "delete", status);
  }
  if (global.json) {
    std::cout << MessageToJson(response);
  } else {
    std::cout << fmt::format("job {} deleted ({} checkpoint file(s), {} bytes freed)", job_id,
                             response.checkpoints_deleted(), response.bytes_freed())
              << std::endl;
  }
  return 0;
}

int Events(const GlobalOptions& global, const std::string& job_id) {
  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  v1::ListJobEventsResponse all;
  all.set_id(job_id);
  std::string token;
  do {
    grpc::ClientContext ctx;
    PrepareUnaryCall(global, &ctx);
    v1::ListJobEventsRequest request;
    request.set_id(job_id);
    request.set_page_size(1000);
    request.set_page_token(token);
    v1::ListJobEventsResponse page;
    if (auto status = stub->ListJobEvents(&ctx, request, &page); !status.ok()) {
      return ReportCallError(global, "events", status);
    }
    for (auto& event : *page.mutable_events()) *all.add_events() = std::move(event);
    token = page.next_page_token();
  } while (!token.empty());
  if (global.json) {
    std::cout << MessageToJson(all);
    return 0;
  }
  std::cout << fmt::format("{:<24}  {:<21} {}", "TIME", "KIND", "MESSAGE") << "\n";
  for (const auto& event : all.events()) std::cout << FormatJobEvent(event) << "\n";
  return 0;
}

}  // namespace seep::client
