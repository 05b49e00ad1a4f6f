// `seep export` and `seep plot` (see field_commands.h): fetch the fields with GetJobFields, the
// time series with GetResult, and write VTK, CSV or SVG files (charts through plot/svg_chart,
// the particle picture through particle_svg).
#include "field_commands.h"

#include <fmt/format.h>
#include <google/protobuf/struct.pb.h>
#include <grpcpp/grpcpp.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "call_support.h"
#include "field_plot.h"
#include "particle_svg.h"
#include "seep/v1/job_service.grpc.pb.h"
#include "vtk_writer.h"

namespace seep::client {
namespace {

template <typename Repeated>
std::vector<double> Doubles(const Repeated& values) {
  return std::vector<double>(values.begin(), values.end());
}

// Writes `content` to dir/name and adds the path to *written; false (after saying why) if not.
bool WriteOutput(const std::filesystem::path& path, const std::string& content,
                 std::vector<std::string>* written) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << content;
  out.flush();
  if (!out) {
    std::fprintf(stderr, "seep: cannot write %s\n", path.string().c_str());
    return false;
  }
  written->push_back(path.string());
  return true;
}

// Columns of doubles as CSV, full precision (shortest round-trip form).
std::string Csv(const std::vector<std::string>& names,
                const std::vector<std::vector<double>>& columns) {
  std::string out;
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (c > 0) out += ',';
    out += names[c];
  }
  out += '\n';
  const std::size_t rows = columns.empty() ? 0 : columns.front().size();
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c > 0) out += ',';
      out += fmt::format("{}", columns[c][r]);
    }
    out += "\n";
  }
  return out;
}

// The domain arrays exported per cell (the analytic ones only where the scene has them).
std::vector<VtkArray> DomainArrays(const v1::JobFields& f) {
  std::vector<VtkArray> arrays = {
      {"pressure_pa", Doubles(f.domain_pressure_pa())},
      {"apparent_volume_m2", Doubles(f.domain_apparent_volume_m2())},
      {"pore_volume_m2", Doubles(f.domain_pore_volume_m2())},
  };
  if (!f.analytic_kind().empty()) {
    arrays.push_back({"analytic_pressure_pa", Doubles(f.domain_analytic_pressure_pa())});
    arrays.push_back({"axis_coordinate_m", Doubles(f.domain_axis_coordinate_m())});
  }
  return arrays;
}

std::vector<VtkArray> PipeArrays(const v1::JobFields& f) {
  return {
      {"flow_m2_per_s", Doubles(f.pipe_flow_m2_per_s())},
      {"aperture_m", Doubles(f.pipe_aperture_m())},
      {"conductance", Doubles(f.pipe_conductance())},
      {"domain_a", Doubles(f.pipe_domain_a())},
      {"domain_b", Doubles(f.pipe_domain_b())},
  };
}

bool WriteStep(const ExportOptions& options, const v1::GetJobFieldsResponse& response,
               std::vector<std::string>* written) {
  const v1::JobFields& f = response.fields();
  const std::filesystem::path dir(options.out_dir);
  const std::uint64_t step = response.step();
  const std::vector<VtkArray> domains = DomainArrays(f);
  const std::vector<VtkArray> pipes = PipeArrays(f);
  if (options.format == "csv") {
    std::vector<std::string> names = {"centroid_x_m", "centroid_y_m"};
    std::vector<std::vector<double>> columns = {Doubles(f.domain_centroid_x_m()),
                                                Doubles(f.domain_centroid_y_m())};
    for (const VtkArray& a : domains) {
      names.push_back(a.name);
      columns.push_back(a.values);
    }
    std::vector<std::string> pipe_names = {"x0_m", "y0_m", "x1_m", "y1_m"};
    std::vector<std::vector<double>> pipe_columns = {Doubles(f.pipe_x0_m()), Doubles(f.pipe_y0_m()),
                                                     Doubles(f.pipe_x1_m()),
                                                     Doubles(f.pipe_y1_m())};
    for (const VtkArray& a : pipes) {
      pipe_names.push_back(a.name);
      pipe_columns.push_back(a.values);
    }
    return WriteOutput(dir / fmt::format("particles_{}.csv", step),
                       Csv({"x_m", "y_m", "radius_m"},
                           {Doubles(f.particle_x_m()), Doubles(f.particle_y_m()),
                            Doubles(f.particle_radius_m())}),
                       written) &&
           WriteOutput(dir / fmt::format("domains_{}.csv", step), Csv(names, columns), written) &&
           WriteOutput(dir / fmt::format("pipes_{}.csv", step), Csv(pipe_names, pipe_columns),
                       written);
  }
  // Loop ids past the particles are wall vertices (walls in the fluid): polygons need both.
  const std::vector<double> px = Doubles(f.particle_x_m());
  const std::vector<double> py = Doubles(f.particle_y_m());
  const std::vector<double> wx = Doubles(f.wall_vertex_x_m());
  const std::vector<double> wy = Doubles(f.wall_vertex_y_m());
  std::vector<double> vx = px, vy = py;
  vx.insert(vx.end(), wx.begin(), wx.end());
  vy.insert(vy.end(), wy.begin(), wy.end());
  const std::vector<std::int32_t> offsets(f.domain_loop_offsets().begin(),
                                          f.domain_loop_offsets().end());
  const std::vector<std::int32_t> loops(f.domain_loop_particles().begin(),
                                        f.domain_loop_particles().end());
  return WriteOutput(dir / fmt::format("particles_{}.vtp", step),
                     VtkPointCloud(px, py, {{"radius_m", Doubles(f.particle_radius_m())}}),
                     written) &&
         WriteOutput(dir / fmt::format("domains_{}.vtu", step),
                     VtkPolygons(vx, vy, offsets, loops, domains), written) &&
         WriteOutput(dir / fmt::format("pipes_{}.vtp", step),
                     VtkSegments(Doubles(f.pipe_x0_m()), Doubles(f.pipe_y0_m()),
                                 Doubles(f.pipe_x1_m()), Doubles(f.pipe_y1_m()), pipes),
                     written);
}

grpc::Status FetchFields(v1::SeepService::Stub& stub, const GlobalOptions& global,
                         const std::string& job_id, std::uint64_t step,
                         v1::GetJobFieldsResponse* response) {
  grpc::ClientContext ctx;
  PrepareUnaryCall(global, &ctx);
  v1::GetJobFieldsRequest request;
  request.set_job_id(job_id);
  request.set_step(step);
  return stub.GetJobFields(&ctx, request, response);
}

// The job's time series, or NOT ok with the call's status (FAILED_PRECONDITION: not SUCCEEDED).
grpc::Status FetchSeries(v1::SeepService::Stub& stub, const GlobalOptions& global,
                         const std::string& job_id, v1::TimeSeries* series) {
  grpc::ClientContext ctx;
  PrepareUnaryCall(global, &ctx);
  v1::GetResultRequest request;
  request.set_id(job_id);
  v1::GetResultResponse response;
  grpc::Status status = stub.GetResult(&ctx, request, &response);
  if (status.ok()) *series = response.result().series();
  return status;
}

std::string SeriesCsv(const v1::TimeSeries& series) {
  std::string out;
  for (int c = 0; c < series.columns_size(); ++c) {
    if (c > 0) out += ',';
    out += series.columns(c);
  }
  out += "\n";
  const int width = series.columns_size();
  for (int i = 0; width > 0 && i < series.values_size(); ++i) {
    out += fmt::format("{}{}", i % width ? "," : "", series.values(i));
    if (i % width == width - 1) out += "\n";
  }
  return out;
}

}  // namespace

FieldCommands AddFieldCommands(CLI::App& app) {
  FieldCommands c;
  c.export_options = std::make_shared<ExportOptions>();
  c.plot_options = std::make_shared<PlotOptions>();
  ExportOptions& e = *c.export_options;
  c.export_cmd = app.add_subcommand(
      "export",
      "write a job's particles, domains (pressure) and pipes (aperture, flow) at a checkpoint as "
      "VTK (.vtp/.vtu for ParaView) or CSV, and its time series as series.csv");
  c.export_cmd->add_option("job", e.job_id, "job id")->required();
  c.export_cmd->add_option("--out", e.out_dir, "directory to write into (created)")->required();
  // A checkpoint's step is >= 1 (the API reads 0 as "the newest", so --step 0 would quietly
  // export another state than the one asked for).
  auto* step = c.export_cmd
                   ->add_option("--step", e.step,
                                "the checkpoint at this step, >= 1 (default: the newest, a "
                                "finished job's end)")
                   ->check(CLI::PositiveNumber);
  c.export_cmd->add_flag("--all-steps", e.all_steps, "every checkpoint the job keeps")
      ->excludes(step);
  c.export_cmd->add_option("--format", e.format, "vtk or csv")
      ->check(CLI::IsMember({"vtk", "csv"}))
      ->capture_default_str();

  PlotOptions& p = *c.plot_options;
  c.plot_cmd = app.add_subcommand(
      "plot",
      "draw an SVG: the pressure profile against the analytic solution, time series, or the "
      "particles with their bonds (intact, broken), the walls and the domain pressure as colour");
  c.plot_cmd->add_option("job", p.job_id, "job id")->required();
  c.plot_cmd->add_option("-o,--out", p.out_file,
                         "the SVG file to write (default: <job>-<what>.svg here)");
  c.plot_cmd->add_option("--what", p.what, "profile, series or particles")
      ->check(CLI::IsMember({"profile", "series", "particles"}))
      ->capture_default_str();
  c.plot_cmd
      ->add_option("--column", p.columns,
                   "series: a column to draw (repeatable; default: all but time_s)")
      ->allow_extra_args(false);  // one name per --column: a following job id stays positional
  c.plot_cmd
      ->add_option("--step", p.step,
                   "profile, particles: the checkpoint at this step, >= 1 (default: newest)")
      ->check(CLI::PositiveNumber);
  return c;
}

int RunFieldCommands(const GlobalOptions& global, const FieldCommands& commands) {
  if (commands.export_cmd != nullptr && *commands.export_cmd) {
    return Export(global, *commands.export_options);
  }
  if (commands.plot_cmd != nullptr && *commands.plot_cmd) {
    return Plot(global, *commands.plot_options);
  }
  return -1;
}

int Export(const GlobalOptions& global, const ExportOptions& options) {
  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec) {
    std::fprintf(stderr, "seep: export: --out %s: %s\n", options.out_dir.c_str(),
                 ec.message().c_str());
    return kExitWriteFailed;
  }
  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  v1::GetJobFieldsResponse first;
  if (auto status = FetchFields(*stub, global, options.job_id, options.step, &first);
      !status.ok()) {
    return ReportCallError(global, "export", status);
  }
  std::vector<std::string> written;
  google::protobuf::ListValue steps;
  // One step, or every step in ascending order (the newest, fetched first, in its place).
  std::vector<std::uint64_t> wanted = {first.step()};
  if (options.all_steps)
    wanted.assign(first.available_steps().begin(), first.available_steps().end());
  for (const std::uint64_t s : wanted) {
    v1::GetJobFieldsResponse more;
    if (s != first.step()) {
      if (auto status = FetchFields(*stub, global, options.job_id, s, &more); !status.ok()) {
        return ReportCallError(global, "export", status);
      }
    }
    if (!WriteStep(options, s == first.step() ? first : more, &written)) return kExitWriteFailed;
    steps.add_values()->set_number_value(static_cast<double>(s));
  }
  v1::TimeSeries series;
  const grpc::Status series_status = FetchSeries(*stub, global, options.job_id, &series);
  if (series_status.ok()) {
    if (!WriteOutput(std::filesystem::path(options.out_dir) / "series.csv", SeriesCsv(series),
                     &written)) {
      return kExitWriteFailed;
    }
  } else if (series_status.error_code() == grpc::StatusCode::FAILED_PRECONDITION) {
    std::fprintf(stderr, "seep: export: no series.csv: %s\n",
                 series_status.error_message().c_str());
  } else {
    return ReportCallError(global, "export (time series)", series_status);
  }
  if (global.json) {
    google::protobuf::Struct out;
    (*out.mutable_fields())["job_id"].set_string_value(options.job_id);
    *(*out.mutable_fields())["steps"].mutable_list_value() = steps;
    auto* files = (*out.mutable_fields())["files"].mutable_list_value();
    for (const std::string& w : written) files->add_values()->set_string_value(w);
    std::cout << MessageToJson(out);
  } else {
    for (const std::string& w : written) std::cout << "wrote " << w << "\n";
  }
  return 0;
}

int Plot(const GlobalOptions& global, const PlotOptions& options) {
  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  std::string svg;
  if (options.what == "profile" || options.what == "particles") {
    v1::GetJobFieldsResponse fields;
    if (auto status = FetchFields(*stub, global, options.job_id, options.step, &fields);
        !status.ok()) {
      return ReportCallError(global, "plot", status);
    }
    if (options.what == "profile") {
      svg = plot::RenderSvg(ProfileChart(options.job_id, fields));
    } else {
      std::string error;
      svg = ParticleSvg(options.job_id, fields, &error);
      if (!error.empty()) {
        std::fprintf(stderr, "seep: plot: %s\n", error.c_str());
        return static_cast<int>(grpc::StatusCode::DATA_LOSS);
      }
    }
  } else {
    v1::TimeSeries series;
    if (auto status = FetchSeries(*stub, global, options.job_id, &series); !status.ok()) {
      return ReportCallError(global, "plot", status);
    }
    std::string error;
    const plot::Chart chart = SeriesChart(options.job_id, series, options.columns, &error);
    if (!error.empty()) {
      std::fprintf(stderr, "seep: plot: %s\n", error.c_str());
      return kBadInput;
    }
    svg = plot::RenderSvg(chart);
  }
  const std::string out_file = options.out_file.empty()
                                   ? fmt::format("{}-{}.svg", options.job_id, options.what)
                                   : options.out_file;
  if (const std::string error = plot::WriteSvgFile(out_file, svg); !error.empty()) {
    std::fprintf(stderr, "seep: plot: %s\n", error.c_str());
    return kExitWriteFailed;
  }
  if (global.json) {
    google::protobuf::Struct out;
    (*out.mutable_fields())["job_id"].set_string_value(options.job_id);
    (*out.mutable_fields())["file"].set_string_value(out_file);
    std::cout << MessageToJson(out);
  } else {
    std::cout << "wrote " << out_file << "\n";
  }
  return 0;
}

}  // namespace seep::client
