#include "commands.h"

#include <fmt/format.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>
#include <grpcpp/grpcpp.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <vector>

#include "call_support.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpc/reflection/v1alpha/reflection.grpc.pb.h"
#include "job_admin_commands.h"
#include "job_printer.h"
#include "scene_file.h"
#include "seep/v1/job_service.grpc.pb.h"

namespace seep::client {
namespace {

// Deadline and token: what every call but WatchJob needs.
void PrepareCall(const GlobalOptions& global, grpc::ClientContext* ctx) {
  ctx->set_deadline(std::chrono::system_clock::now() +
                    std::chrono::milliseconds(static_cast<long>(global.timeout_s * 1000)));
  AddToken(global, ctx);
}

// Width of the terminal on stdout; 80 when it cannot be told.
int TerminalColumns() {
  winsize size{};
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  return 80;
}

}  // namespace

int LoadCredentials(GlobalOptions* global) {
  if (const std::string problem = LoadConnectionSecrets(*global); !problem.empty()) {
    std::fprintf(stderr, "seep: %s\n", problem.c_str());
    return static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT);
  }
  return 0;
}

namespace {

int ReportRpcError(const GlobalOptions& global, const char* what, const grpc::Status& status) {
  if (status.error_code() == grpc::StatusCode::UNAVAILABLE ||
      status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED) {
    // A TLS mismatch looks like an unreachable server to gRPC: say which side to check.
    const std::string& message = status.error_message();
    const char* hint = "";
    if (message.find("Ssl handshake failed") != std::string::npos) {
      hint = " (TLS: is --tls-ca the certificate seepd serves?)";
    } else if (!global.tls && global.tls_ca.empty() &&
               message.find("Socket closed") != std::string::npos) {
      hint = " (if seepd serves TLS, connect with --tls-ca or --tls)";
    }
    std::fprintf(stderr, "seep: %s: server %s unreachable: %s%s\n", what, global.server.c_str(),
                 message.c_str(), hint);
    return static_cast<int>(grpc::StatusCode::UNAVAILABLE);
  }
  std::fprintf(stderr, "seep: %s: %s\n", what, status.error_message().c_str());
  return static_cast<int>(status.error_code());
}

std::string ToJson(const google::protobuf::Message& message) {
  std::string json;
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  (void)google::protobuf::util::MessageToJsonString(message, &json, options);
  return json;
}

int ExitCodeFor(const v1::Job& job) {
  switch (job.state()) {
    case v1::JOB_STATE_FAILED:
      return kExitJobFailed;
    case v1::JOB_STATE_CANCELLED:
      return kExitJobCancelled;
    default:
      return 0;
  }
}

bool IsTerminal(v1::JobState s) {
  return s == v1::JOB_STATE_SUCCEEDED || s == v1::JOB_STATE_FAILED || s == v1::JOB_STATE_CANCELLED;
}

// A client-chosen idempotency key, printed so that a user can retry the same submission.
std::string NewRequestId() {
  std::random_device rd;
  std::mt19937_64 rng((static_cast<std::uint64_t>(rd()) << 32) ^ rd());
  return fmt::format("r-{:016x}", rng());
}

}  // namespace

int Submit(const GlobalOptions& global, const SubmitOptions& options) {
  const bool fork = !options.from_job_id.empty();
  const char* command = fork ? "fork" : "submit";
  v1::SubmitJobRequest request;
  MessageFile file;
  if (const std::string error = file.Load(options.scene_file, request.mutable_scene(), "scene");
      !error.empty()) {
    // "FILE:LINE:COL: ..." first on the line, as compilers print it, so editors can jump there.
    std::fprintf(stderr, "%s\n", error.c_str());
    return static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT);
  }
  if (!options.name.empty()) request.mutable_scene()->set_name(options.name);
  request.set_request_id(options.request_id.empty() ? NewRequestId() : options.request_id);
  request.set_priority(options.priority);
  if (const std::string bad = ParseLabelOptions(options.labels, request.mutable_labels());
      !bad.empty()) {
    std::fprintf(stderr, "seep: %s: %s\n", command, bad.c_str());
    return static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT);
  }
  if (fork) {
    request.set_from_job_id(options.from_job_id);
    if (options.from_step) request.set_from_step(*options.from_step);
  }

  auto stub = v1::SeepService::NewStub(OpenSeepdChannel(global));
  grpc::ClientContext ctx;
  PrepareCall(global, &ctx);
  v1::SubmitJobResponse response;
  if (auto status = stub->SubmitJob(&ctx, request, &response); !status.ok()) {
    // Labels and the fork's parent are not in the file.
    const std::string& message = status.error_message();
    if (status.error_code() == grpc::StatusCode::INVALID_ARGUMENT &&
        message.rfind("labels", 0) != 0 && message.rfind("from_", 0) != 0) {
      // The server names the field ("scene.fluid.viscosity_pa_s: ..."): add the file and line.
      std::fprintf(stderr, "%s\n", file.PointAt(message, "scene").c_str());
      return static_cast<int>(status.error_code());
    }
    return ReportRpcError(global, command, status);
  }
  const std::string forked =
      fork ? fmt::format(", forked from job {} at step {}", response.job().parent_job_id(),
                         response.job().parent_step())
           : std::string();
  const std::string submitted =
      fmt::format("submitted job {} ({}, request id {}){}", response.job().id(),
                  response.created() ? "new" : "already submitted", request.request_id(), forked);
  if (global.json && !options.watch) {
    std::cout << ToJson(response.job());
  } else if (global.json) {
    // stdout stays one JSON document (the finished job); the id still reaches the user.
    std::cerr << submitted << std::endl;
  } else {
    std::cout << submitted << std::endl;
  }
  return options.watch ? Watch(global, response.job().id()) : 0;
}

int Watch(const GlobalOptions& global, const std::string& job_id) {
  auto stub = v1::SeepService::NewStub(OpenSeepdChannel(global));
  grpc::ClientContext ctx;  // no deadline: a watch lasts as long as the job
  AddToken(global, &ctx);
  v1::WatchJobRequest request;
  request.set_id(job_id);
  auto reader = stub->WatchJob(&ctx, request);
  const bool tty = isatty(STDOUT_FILENO) != 0;
  v1::JobEvent event;
  v1::Job last;
  std::string last_line;
  v1::JobState last_state = v1::JOB_STATE_UNSPECIFIED;
  auto last_print = std::chrono::steady_clock::now() - std::chrono::hours(1);
  while (reader->Read(&event)) {
    last = event.job();
    if (global.json) continue;
    const auto now = std::chrono::steady_clock::now();
    if (tty) {
      // Redrawn in place at most ten times a second: a terminal shows the newest state anyway.
      if (last.state() == last_state && now - last_print < std::chrono::milliseconds(100)) continue;
      const std::string line = FormatProgressBar(last, TerminalColumns());
      if (line == last_line) continue;
      std::cout << "\r\033[K" << line << std::flush;
      last_line = line;
    } else {
      // Logs and pipes get whole lines: one per state change and at most one a second between.
      const std::string line = FormatProgress(last);
      if (line == last_line) continue;
      if (last.state() == last_state && now - last_print < std::chrono::seconds(1)) continue;
      std::cout << line << "\n" << std::flush;
      last_line = line;
    }
    last_state = last.state();
    last_print = now;
  }
  if (!global.json && !last_line.empty()) {
    // The final state is always shown, even when it came inside a throttled interval.
    const std::string line =
        tty ? FormatProgressBar(last, TerminalColumns()) : FormatProgress(last);
    if (tty) {
      std::cout << (line == last_line ? std::string() : "\r\033[K" + line) << "\n";
    } else if (line != last_line) {
      std::cout << line << "\n";
    }
  }
  if (auto status = reader->Finish(); !status.ok()) return ReportRpcError(global, "watch", status);
  if (!IsTerminal(last.state())) {
    std::fprintf(stderr, "seep: watch: stream ended before job %s finished\n", job_id.c_str());
    return static_cast<int>(grpc::StatusCode::UNAVAILABLE);
  }
  // The stream leaves out the scene and may lag the final write: read the job once more.
  if (const int shown = Show(global, job_id); shown != 0) return shown;
  return ExitCodeFor(last);
}

int Show(const GlobalOptions& global, const std::string& job_id) {
  auto stub = v1::SeepService::NewStub(OpenSeepdChannel(global));
  grpc::ClientContext ctx;
  PrepareCall(global, &ctx);
  v1::GetJobRequest request;
  request.set_id(job_id);
  v1::GetJobResponse response;
  if (auto status = stub->GetJob(&ctx, request, &response); !status.ok()) {
    return ReportRpcError(global, "show", status);
  }
  if (global.json) {
    std::cout << ToJson(response.job());
  } else {
    std::cout << FormatJob(response.job());
  }
  return 0;
}

int List(const GlobalOptions& global, const ListOptions& options) {
  const unsigned limit = options.limit;
  std::vector<v1::JobState> states;
  for (const std::string& name : options.states) {
    std::string upper = "JOB_STATE_";
    for (const char c : name)
      upper += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    v1::JobState state = v1::JOB_STATE_UNSPECIFIED;
    if (!v1::JobState_Parse(upper, &state) || state == v1::JOB_STATE_UNSPECIFIED) {
      std::fprintf(stderr,
                   "seep: list: --state %s: expected queued, running, succeeded, failed or "
                   "cancelled\n",
                   name.c_str());
      return static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT);
    }
    states.push_back(state);
  }
  std::vector<v1::JobKind> kinds;
  for (const std::string& name : options.kinds) {
    std::string upper = "JOB_KIND_";
    for (const char c : name)
      upper += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    v1::JobKind kind = v1::JOB_KIND_UNSPECIFIED;
    if (!v1::JobKind_Parse(upper, &kind) || kind == v1::JOB_KIND_UNSPECIFIED) {
      std::fprintf(stderr, "seep: list: --kind %s: expected simulation or calibration\n",
                   name.c_str());
      return static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT);
    }
    kinds.push_back(kind);
  }
  google::protobuf::Map<std::string, std::string> labels;
  if (const std::string bad = ParseLabelOptions(options.labels, &labels); !bad.empty()) {
    std::fprintf(stderr, "seep: list: %s\n", bad.c_str());
    return static_cast<int>(grpc::StatusCode::INVALID_ARGUMENT);
  }
  auto stub = v1::SeepService::NewStub(OpenSeepdChannel(global));
  v1::ListJobsResponse all;
  std::string token;
  do {
    grpc::ClientContext ctx;
    PrepareCall(global, &ctx);
    v1::ListJobsRequest request;
    request.set_page_size(std::min(limit - static_cast<unsigned>(all.jobs_size()), 1000u));
    request.set_page_token(token);
    for (const v1::JobState state : states) request.add_states(state);
    request.set_name_contains(options.name_contains);
    for (const v1::JobKind kind : kinds) request.add_kinds(kind);
    *request.mutable_labels() = labels;
    v1::ListJobsResponse page;
    if (auto status = stub->ListJobs(&ctx, request, &page); !status.ok()) {
      return ReportRpcError(global, "list", status);
    }
    for (auto& job : *page.mutable_jobs()) *all.add_jobs() = std::move(job);
    token = page.next_page_token();
  } while (!token.empty() && static_cast<unsigned>(all.jobs_size()) < limit);
  if (global.json) {
    std::cout << ToJson(all);
    return 0;
  }
  std::cout << FormatJobTableHeader() << "\n";
  for (const auto& job : all.jobs()) std::cout << FormatJobRow(job) << "\n";
  return 0;
}

int Cancel(const GlobalOptions& global, const std::string& job_id) {
  auto stub = v1::SeepService::NewStub(OpenSeepdChannel(global));
  grpc::ClientContext ctx;
  PrepareCall(global, &ctx);
  v1::CancelJobRequest request;
  request.set_id(job_id);
  v1::CancelJobResponse response;
  if (auto status = stub->CancelJob(&ctx, request, &response); !status.ok()) {
    return ReportRpcError(global, "cancel", status);
  }
  if (global.json) {
    std::cout << ToJson(response.job());
  } else if (response.job().state() == v1::JOB_STATE_CANCELLED) {
    std::cout << fmt::format("job {} cancelled", job_id) << std::endl;
  } else {
    std::cout << fmt::format("job {} is {}; cancel requested, it stops at its next step", job_id,
                             StateName(response.job().state()))
              << std::endl;
  }
  return 0;
}

int Resume(const GlobalOptions& global, const std::string& job_id) {
  auto stub = v1::SeepService::NewStub(OpenSeepdChannel(global));
  grpc::ClientContext ctx;
  PrepareCall(global, &ctx);
  v1::ResumeJobRequest request;
  request.set_id(job_id);
  v1::ResumeJobResponse response;
  if (auto status = stub->ResumeJob(&ctx, request, &response); !status.ok()) {
    return ReportRpcError(global, "resume", status);
  }
  if (global.json) {
    std::cout << ToJson(response.job());
  } else {
    std::cout << fmt::format("job {} queued again (attempt {})", job_id, response.job().attempt())
              << std::endl;
  }
  return 0;
}

int Result(const GlobalOptions& global, const std::string& job_id) {
  auto stub = v1::SeepService::NewStub(OpenSeepdChannel(global));
  grpc::ClientContext ctx;
  PrepareCall(global, &ctx);
  v1::GetResultRequest request;
  request.set_id(job_id);
  v1::GetResultResponse response;
  if (auto status = stub->GetResult(&ctx, request, &response); !status.ok()) {
    return ReportRpcError(global, "result", status);
  }
  if (global.json) {
    std::cout << ToJson(response);
  } else {
    std::cout << FormatResult(response.result());
  }
  return 0;
}

int Health(const GlobalOptions& global) {
  auto channel = OpenSeepdChannel(global);
  auto health = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext ctx;
  PrepareCall(global, &ctx);
  grpc::health::v1::HealthCheckRequest request;
  grpc::health::v1::HealthCheckResponse response;
  if (auto status = health->Check(&ctx, request, &response); !status.ok()) {
    return ReportRpcError(global, "health", status);
  }
  const std::string serving =
      grpc::health::v1::HealthCheckResponse::ServingStatus_Name(response.status());

  // Which services the server offers, through gRPC server reflection (v1alpha in gRPC 1.51).
  auto reflection = grpc::reflection::v1alpha::ServerReflection::NewStub(channel);
  grpc::ClientContext rctx;
  PrepareCall(global, &rctx);
  auto stream = reflection->ServerReflectionInfo(&rctx);
  grpc::reflection::v1alpha::ServerReflectionRequest list;
  list.set_list_services("");
  grpc::reflection::v1alpha::ServerReflectionResponse listed;
  std::vector<std::string> services;
  if (stream->Write(list) && stream->WritesDone() && stream->Read(&listed)) {
    for (const auto& s : listed.list_services_response().service()) services.push_back(s.name());
  }
  if (auto status = stream->Finish(); !status.ok()) {
    return ReportRpcError(global, "health (reflection)", status);
  }
  if (global.json) {
    // {"server": ..., "status": "SERVING", "services": [...]}: a Struct, printed by protobuf.
    google::protobuf::Struct out;
    (*out.mutable_fields())["server"].set_string_value(global.server);
    (*out.mutable_fields())["status"].set_string_value(serving);
    auto* names = (*out.mutable_fields())["services"].mutable_list_value();
    for (const std::string& name : services) names->add_values()->set_string_value(name);
    std::cout << ToJson(out);
  } else {
    std::cout << "status   " << serving << "\n";
    for (const std::string& name : services) std::cout << "service  " << name << "\n";
  }
  return response.status() == grpc::health::v1::HealthCheckResponse::SERVING
             ? 0
             : static_cast<int>(grpc::StatusCode::UNAVAILABLE);
}

// The helpers above, for the other command files (call_support.h).
std::shared_ptr<grpc::Channel> OpenChannel(const GlobalOptions& global) {
  return OpenSeepdChannel(global);
}
void PrepareUnaryCall(const GlobalOptions& global, grpc::ClientContext* ctx) {
  PrepareCall(global, ctx);
}
int ReportCallError(const GlobalOptions& global, const char* what, const grpc::Status& status) {
  return ReportRpcError(global, what, status);
}
std::string MessageToJson(const google::protobuf::Message& message) { return ToJson(message); }
std::string NewSubmitRequestId() { return NewRequestId(); }
int StdoutColumns() { return TerminalColumns(); }

}  // namespace seep::client
