// `seep sweep ...` (see sweep_commands.h): SubmitSweep, GetSweep (polled by --watch),
// CancelSweep, ResumeSweep and DeleteSweep, shown with sweep_table.h and sweep_plot.h.
#include "sweep_commands.h"

#include <fmt/format.h>
#include <google/protobuf/struct.pb.h>
#include <grpcpp/grpcpp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <thread>

#include "call_support.h"
#include "field_commands.h"
#include "job_admin_commands.h"
#include "scene_file.h"
#include "seep/v1/job_service.grpc.pb.h"
#include "sweep_plot.h"
#include "sweep_table.h"

namespace seep::client {
namespace {

// One call on sweep `id` (GetSweep, CancelSweep, ...); prints what failed and returns the exit
// code, 0 when the call succeeded.
template <typename Request, typename Response>
int CallOnSweep(const GlobalOptions& global, v1::SeepService::Stub& stub, const char* what,
                grpc::Status (v1::SeepService::Stub::*method)(grpc::ClientContext*, const Request&,
                                                              Response*),
                const std::string& id, Response* response) {
  grpc::ClientContext ctx;
  PrepareUnaryCall(global, &ctx);
  Request request;
  request.set_id(id);
  if (auto status = (stub.*method)(&ctx, request, response); !status.ok()) {
    return ReportCallError(global, what, status);
  }
  return 0;
}

int FetchSweep(const GlobalOptions& global, v1::SeepService::Stub& stub, const char* what,
               const std::string& id, v1::GetSweepResponse* response) {
  return CallOnSweep(global, stub, what, &v1::SeepService::Stub::GetSweep, id, response);
}

int SweepExitCode(const v1::SweepStatus& sweep) {
  if (sweep.counts().failed() > 0) return kExitJobFailed;
  if (sweep.counts().cancelled() > 0) return kExitJobCancelled;
  return 0;
}

// Polls the sweep until every job has finished: one line for the whole sweep, redrawn in place
// on a terminal, else printed on each change and at most once a second. Then the table of its
// parameters and job states.
int WatchSweep(const GlobalOptions& global, const std::string& id) {
  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  const bool tty = isatty(STDOUT_FILENO) != 0;
  std::string last_line;
  auto last_print = std::chrono::steady_clock::now() - std::chrono::hours(1);
  v1::GetSweepResponse response;
  for (;;) {
    response.Clear();
    if (const int failed = FetchSweep(global, *stub, "sweep watch", id, &response); failed != 0) {
      return failed;
    }
    const bool finished = SweepFinished(response.sweep());
    std::string line = FormatSweepProgress(response.sweep());
    // A wrapped line could not be redrawn in place: a terminal gets it cut to its width.
    const auto columns = static_cast<std::size_t>(std::max(StdoutColumns() - 1, 20));
    if (tty && line.size() > columns) line.resize(columns);
    const auto now = std::chrono::steady_clock::now();
    const bool due = now - last_print >= std::chrono::seconds(1) || finished;
    if (!global.json && line != last_line && (tty || due)) {
      std::cout << (tty ? "\r\033[K" : "") << line << (tty ? "" : "\n") << std::flush;
      last_line = line;
      last_print = now;
    }
    if (finished) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  if (global.json) {
    std::cout << MessageToJson(response.sweep());
  } else {
    // The parameters and states only: `seep sweep show --metrics` picks the metrics to see.
    if (tty) std::cout << "\n";
    std::cout << FormatSweepTable(response.sweep(), {});
  }
  return SweepExitCode(response.sweep());
}

int SubmitSweep(const GlobalOptions& global, const SweepOptions& options) {
  v1::SubmitSweepRequest request;
  MessageFile file;
  if (const std::string error = file.Load(options.file, request.mutable_sweep(), "sweep");
      !error.empty()) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return kBadInput;
  }
  request.set_request_id(options.request_id.empty() ? NewSubmitRequestId() : options.request_id);
  request.set_priority(options.priority);
  if (const std::string bad = ParseLabelOptions(options.labels, request.mutable_labels());
      !bad.empty()) {
    std::fprintf(stderr, "seep: sweep submit: %s\n", bad.c_str());
    return kBadInput;
  }
  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  grpc::ClientContext ctx;
  PrepareUnaryCall(global, &ctx);
  v1::SubmitSweepResponse response;
  if (auto status = stub->SubmitSweep(&ctx, request, &response); !status.ok()) {
    if (status.error_code() == grpc::StatusCode::INVALID_ARGUMENT &&
        status.error_message().rfind("sweep", 0) == 0) {
      // "sweep.axes[0].numbers[2]: ...": the file and the line where that value is written.
      std::fprintf(stderr, "%s\n", file.PointAt(status.error_message(), "sweep").c_str());
      return kBadInput;
    }
    return ReportCallError(global, "sweep submit", status);
  }
  const v1::SweepStatus& sweep = response.sweep();
  const std::string submitted = fmt::format(
      "submitted sweep {} with {} jobs ({}, request id {})", sweep.id(), sweep.jobs_size(),
      response.created() ? "new" : "already submitted", request.request_id());
  if (global.json && !options.watch) {
    std::cout << MessageToJson(sweep);
  } else {
    (global.json ? std::cerr : std::cout) << submitted << std::endl;
  }
  return options.watch ? WatchSweep(global, sweep.id()) : 0;
}

int ShowSweep(const GlobalOptions& global, const SweepOptions& options) {
  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  v1::GetSweepResponse response;
  if (const int failed = FetchSweep(global, *stub, "sweep show", options.sweep_id, &response);
      failed != 0) {
    return failed;
  }
  if (global.json) {
    std::cout << MessageToJson(response.sweep());
    return 0;
  }
  std::string error;
  const auto metrics = SweepMetricColumns(response.sweep(), options.metrics, &error);
  if (!error.empty()) {
    std::fprintf(stderr, "seep: sweep show: %s\n", error.c_str());
    return kBadInput;
  }
  if (options.csv) {
    std::cout << FormatSweepCsv(response.sweep(), metrics);
  } else {
    std::cout << FormatSweepProgress(response.sweep()) << "\n"
              << FormatSweepTable(response.sweep(), metrics);
  }
  return 0;
}

int PlotSweep(const GlobalOptions& global, const SweepOptions& options) {
  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  v1::GetSweepResponse response;
  if (const int failed = FetchSweep(global, *stub, "sweep plot", options.sweep_id, &response);
      failed != 0) {
    return failed;
  }
  std::string error;
  const SweepChartRequest request{options.x_path, options.y_metric, options.log_x, options.log_y};
  const plot::Chart chart = SweepChart(response.sweep(), request, &error);
  if (!error.empty()) {
    std::fprintf(stderr, "seep: sweep plot: %s\n", error.c_str());
    return kBadInput;
  }
  if (const std::string failed = plot::WriteSvgFile(options.out_file, plot::RenderSvg(chart));
      !failed.empty()) {
    std::fprintf(stderr, "seep: sweep plot: %s\n", failed.c_str());
    return kExitWriteFailed;
  }
  if (global.json) {
    google::protobuf::Struct out;
    (*out.mutable_fields())["sweep_id"].set_string_value(options.sweep_id);
    (*out.mutable_fields())["file"].set_string_value(options.out_file);
    std::cout << MessageToJson(out);
  } else {
    std::cout << fmt::format("wrote {}", options.out_file) << std::endl;
  }
  return 0;
}

// cancel, resume and delete: one call on the sweep, then its response as JSON or as the line
// `describe` makes of it.
template <typename Request, typename Response>
int ActOnSweep(const GlobalOptions& global, const char* what,
               grpc::Status (v1::SeepService::Stub::*method)(grpc::ClientContext*, const Request&,
                                                             Response*),
               const std::string& id, std::string (*describe)(const Response&)) {
  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  Response response;
  if (const int failed = CallOnSweep(global, *stub, what, method, id, &response); failed != 0) {
    return failed;
  }
  if (global.json) {
    std::cout << MessageToJson(response);
  } else {
    std::cout << describe(response) << std::endl;
  }
  return 0;
}

std::string DescribeCancel(const v1::CancelSweepResponse& r) {
  return fmt::format(
      "sweep {}: {} queued job(s) cancelled, {} running job(s) stop at their next "
      "step",
      r.sweep().id(), r.jobs_cancelled(), r.cancels_requested());
}

std::string DescribeResume(const v1::ResumeSweepResponse& r) {
  return fmt::format("sweep {}: {} job(s) queued again", r.sweep().id(), r.jobs_resumed());
}

std::string DescribeDelete(const v1::DeleteSweepResponse& r) {
  return fmt::format("sweep {} deleted with {} job(s) ({} checkpoint file(s), {} bytes freed)",
                     r.id(), r.jobs_deleted(), r.checkpoints_deleted(), r.bytes_freed());
}

}  // namespace

SweepCommands AddSweepCommands(CLI::App& app) {
  SweepCommands c;
  c.options = std::make_shared<SweepOptions>();
  SweepOptions& o = *c.options;
  c.sweep_cmd = app.add_subcommand(
      "sweep",
      "many runs from one base scene: submit a seep.v1.Sweep file, follow, tabulate, "
      "plot, cancel, resume or delete it as a whole");
  c.sweep_cmd->require_subcommand(1);
  c.submit_cmd = c.sweep_cmd->add_subcommand("submit", "queue every job of a sweep file");
  c.submit_cmd->add_option("file", o.file, "sweep file (.textproto or .json)")->required();
  c.submit_cmd->add_option("--request-id", o.request_id,
                           "idempotency key: submitting it again returns the same sweep");
  c.submit_cmd->add_option("--priority", o.priority,
                           "priority of every job (-1000 to 1000; default 0)");
  c.submit_cmd->add_option("--label", o.labels,
                           "a KEY=VALUE label of every job (seep list --label); repeatable");
  c.submit_cmd->add_flag("--watch", o.watch, "follow the sweep until every job has finished");
  c.show_cmd = c.sweep_cmd->add_subcommand(
      "show", "a table of the swept parameters against result metrics and job states");
  c.show_cmd->add_option("sweep", o.sweep_id, "sweep id")->required();
  c.show_cmd->add_option("--metrics", o.metrics, "the metric columns, e.g. a,b (default: all)")
      ->delimiter(',');
  c.show_cmd->add_flag("--csv", o.csv, "print CSV (every number in full precision)");
  c.plot_cmd = c.sweep_cmd->add_subcommand("plot", "an SVG of a metric against a swept parameter");
  c.plot_cmd->add_option("sweep", o.sweep_id, "sweep id")->required();
  c.plot_cmd->add_option("--x", o.x_path, "the swept parameter (its field path)")->required();
  c.plot_cmd->add_option("--y", o.y_metric, "the result metric")->required();
  c.plot_cmd->add_option("--out", o.out_file, "SVG file to write")->required();
  c.plot_cmd->add_flag("--log-x", o.log_x, "log10 scale for the parameter");
  c.plot_cmd->add_flag("--log-y", o.log_y, "log10 scale for the metric");
  c.cancel_cmd = c.sweep_cmd->add_subcommand("cancel", "cancel every queued or running job");
  c.cancel_cmd->add_option("sweep", o.sweep_id, "sweep id")->required();
  c.resume_cmd = c.sweep_cmd->add_subcommand("resume", "run every failed or cancelled job again");
  c.resume_cmd->add_option("sweep", o.sweep_id, "sweep id")->required();
  c.delete_cmd = c.sweep_cmd->add_subcommand(
      "delete", "delete a finished sweep with all its jobs, results and checkpoint files");
  c.delete_cmd->add_option("sweep", o.sweep_id, "sweep id")->required();
  return c;
}

int RunSweepCommands(const GlobalOptions& global, const SweepCommands& commands) {
  if (!*commands.sweep_cmd) return -1;
  const SweepOptions& o = *commands.options;
  if (*commands.submit_cmd) return SubmitSweep(global, o);
  if (*commands.show_cmd) return ShowSweep(global, o);
  if (*commands.plot_cmd) return PlotSweep(global, o);
  if (*commands.cancel_cmd) {
    return ActOnSweep(global, "sweep cancel", &v1::SeepService::Stub::CancelSweep, o.sweep_id,
                      &DescribeCancel);
  }
  if (*commands.resume_cmd) {
    return ActOnSweep(global, "sweep resume", &v1::SeepService::Stub::ResumeSweep, o.sweep_id,
                      &DescribeResume);
  }
  if (*commands.delete_cmd) {
    return ActOnSweep(global, "sweep delete", &v1::SeepService::Stub::DeleteSweep, o.sweep_id,
                      &DescribeDelete);
  }
  return kExitUsage;
}

}  // namespace seep::client
