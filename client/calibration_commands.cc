// seep calibrate, seep calibrations and seep calibrations lookup (calibration_commands.h).
#include "calibration_commands.h"

#include <fmt/format.h>
#include <google/protobuf/util/time_util.h>

#include <cstdio>
#include <iostream>

#include "call_support.h"
#include "job_admin_commands.h"
#include "scene_file.h"
#include "seep/v1/job_service.grpc.pb.h"

namespace seep::client {
namespace {

std::string FormatTimestamp(const google::protobuf::Timestamp& t) {
  if (t.seconds() == 0 && t.nanos() == 0) return "-";
  return google::protobuf::util::TimeUtil::ToString(t);
}

std::string JoinTags(const v1::CalibrationRecord& r, const char* separator) {
  std::string out;
  for (int i = 0; i < r.tags_size(); ++i) {
    if (i > 0) out += separator;
    out += r.tags(i);
  }
  return out;
}

std::string TableHeader() {
  return fmt::format(
      "{:<20} {:>3} {:>11} {:>12} {:>11} {:>9} {:>3} {:>9} {:>6} {:>8} {:>10} "
      "{:>5}  {:<20} {}",
      "JOB", "#", "TARGET_K_M2", "A0_M", "K_M2", "REL_ERR", "IT", "FIRST_ERR", "N", "POROSITY",
      "MEAN_R_M", "Z", "CREATED", "TAGS");
}

std::string TableRow(const v1::CalibrationRecord& r) {
  return fmt::format(
      "{:<20} {:>3} {:>11.4e} {:>12.6e} {:>11.4e} {:>9.2e} {:>3} {:>9.2e} {:>6} {:>8.5f} "
      "{:>10.4e} {:>5.2f}  {:<20} {}",
      r.job_id(), r.target_index(), r.target_permeability_m2(), r.residual_aperture_m(),
      r.permeability_m2(), r.relative_error(), r.iterations(), r.first_guess_relative_error(),
      r.packing().particle_count(), r.packing().porosity_2d(), r.packing().mean_radius_m(),
      r.packing().coordination_number(), FormatTimestamp(r.created_at()), JoinTags(r, ","));
}

// Full precision (17 significant digits round-trip a double) for spreadsheets and scripts.
constexpr const char* kCsvHeader =
    "job_id,target_index,target_permeability_m2,residual_aperture_m,permeability_m2,"
    "relative_error,converged,tolerance,iterations,corrections,first_guess_residual_aperture_m,"
    "first_guess_permeability_m2,first_guess_relative_error,particle_count,contact_count,"
    "pipe_count,porosity_2d,mean_radius_m,radius_std_dev_m,coordination_number,viscosity_pa_s,"
    "bulk_modulus_pa,reference_force_n,gap_multiplier,max_aperture_m,uniform_normal_force_n,"
    "pipes_in_compression,pipes_open,flow_axis,pressure_drop_pa,scene_sha256,build_id,"
    "created_at,tags";

std::string CsvRow(const v1::CalibrationRecord& r) {
  const auto& p = r.packing();
  return fmt::format(
      "{},{},{:.17g},{:.17g},{:.17g},{:.17g},{},{:.17g},{},{},{:.17g},{:.17g},{:.17g},{},{},{},"
      "{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{},{},{},"
      "{:.17g},{},{},{},{}",
      r.job_id(), r.target_index(), r.target_permeability_m2(), r.residual_aperture_m(),
      r.permeability_m2(), r.relative_error(), r.converged() ? 1 : 0, r.tolerance(), r.iterations(),
      r.corrections(), r.first_guess_residual_aperture_m(), r.first_guess_permeability_m2(),
      r.first_guess_relative_error(), p.particle_count(), p.contact_count(), p.pipe_count(),
      p.porosity_2d(), p.mean_radius_m(), p.radius_std_dev_m(), p.coordination_number(),
      r.fluid().viscosity_pa_s(), r.fluid().bulk_modulus_pa(), r.aperture().reference_force_n(),
      r.aperture().gap_multiplier(), r.aperture().max_aperture_m(),
      r.stress().uniform_normal_force_n(), r.stress().pipes_in_compression(),
      r.stress().pipes_open(), r.flow_axis() == v1::FLOW_AXIS_Y ? "y" : "x", r.pressure_drop_pa(),
      r.scene_sha256(), r.build_id(), FormatTimestamp(r.created_at()), JoinTags(r, ";"));
}

bool ParseTime(const std::string& text, const char* flag, google::protobuf::Timestamp* out) {
  if (google::protobuf::util::TimeUtil::FromString(text, out)) return true;
  std::fprintf(stderr,
               "seep: calibrations: %s %s: expected an RFC 3339 time such as "
               "2026-11-23T00:00:00Z\n",
               flag, text.c_str());
  return false;
}

}  // namespace

int Calibrate(const GlobalOptions& global, const CalibrateOptions& options) {
  v1::SubmitJobRequest request;
  v1::Calibration* calibration = request.mutable_calibration();
  MessageFile file;
  if (const std::string error = file.Load(options.file, calibration, "calibration");
      !error.empty()) {
    std::fprintf(stderr, "%s\n", error.c_str());  // FILE:LINE:COL first, as compilers print it
    return kBadInput;
  }
  if (!options.name.empty()) calibration->set_name(options.name);
  if (!options.from_job.empty()) calibration->set_from_job_id(options.from_job);
  for (const std::string& tag : options.tags) calibration->add_tags(tag);
  request.set_request_id(options.request_id.empty() ? NewSubmitRequestId() : options.request_id);
  if (const std::string bad = ParseLabelOptions(options.labels, request.mutable_labels());
      !bad.empty()) {
    std::fprintf(stderr, "seep: calibrate: %s\n", bad.c_str());
    return kBadInput;
  }

  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  grpc::ClientContext ctx;
  PrepareUnaryCall(global, &ctx);
  v1::SubmitJobResponse response;
  if (auto status = stub->SubmitJob(&ctx, request, &response); !status.ok()) {
    if (status.error_code() == grpc::StatusCode::INVALID_ARGUMENT &&
        status.error_message().rfind("labels", 0) != 0) {
      // "calibration.target_permeabilities_m2[3]: ..." gets the file and the line of that field.
      std::fprintf(stderr, "%s\n", file.PointAt(status.error_message(), "calibration").c_str());
      return kBadInput;
    }
    return ReportCallError(global, "calibrate", status);
  }
  const std::string submitted =
      fmt::format("submitted calibration job {} ({}, {} target(s), request id {})",
                  response.job().id(), response.created() ? "new" : "already submitted",
                  calibration->target_permeabilities_m2_size(), request.request_id());
  if (global.json && !options.watch) {
    std::cout << MessageToJson(response.job());
  } else if (global.json) {
    std::cerr << submitted << std::endl;  // stdout stays one JSON document
  } else {
    std::cout << submitted << std::endl;
  }
  return options.watch ? Watch(global, response.job().id()) : 0;
}

int ListCalibrations(const GlobalOptions& global, const CalibrationListOptions& options) {
  v1::ListCalibrationsRequest filter;
  if (options.k_min) filter.set_min_permeability_m2(*options.k_min);
  if (options.k_max) filter.set_max_permeability_m2(*options.k_max);
  if (options.porosity_min) filter.set_min_porosity(*options.porosity_min);
  if (options.porosity_max) filter.set_max_porosity(*options.porosity_max);
  if (options.radius_min) filter.set_min_mean_radius_m(*options.radius_min);
  if (options.radius_max) filter.set_max_mean_radius_m(*options.radius_max);
  for (const std::string& tag : options.tags) filter.add_tags(tag);
  if (!options.after.empty() &&
      !ParseTime(options.after, "--after", filter.mutable_created_after())) {
    return kBadInput;
  }
  if (!options.before.empty() &&
      !ParseTime(options.before, "--before", filter.mutable_created_before())) {
    return kBadInput;
  }
  filter.set_job_id(options.job);

  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  v1::ListCalibrationsResponse all;
  std::string token;
  do {
    grpc::ClientContext ctx;
    PrepareUnaryCall(global, &ctx);
    v1::ListCalibrationsRequest request = filter;
    request.set_page_size(
        std::min(options.limit - static_cast<unsigned>(all.records_size()), 1000u));
    request.set_page_token(token);
    v1::ListCalibrationsResponse page;
    if (auto status = stub->ListCalibrations(&ctx, request, &page); !status.ok()) {
      return ReportCallError(global, "calibrations", status);
    }
    for (auto& r : *page.mutable_records()) *all.add_records() = std::move(r);
    token = page.next_page_token();
  } while (!token.empty() && static_cast<unsigned>(all.records_size()) < options.limit);

  if (global.json) {
    std::cout << MessageToJson(all);
  } else if (options.csv) {
    std::cout << kCsvHeader << "\n";
    for (const auto& r : all.records()) std::cout << CsvRow(r) << "\n";
  } else {
    std::cout << TableHeader() << "\n";
    for (const auto& r : all.records()) std::cout << TableRow(r) << "\n";
  }
  return 0;
}

int LookupCalibration(const GlobalOptions& global, const CalibrationLookupOptions& options) {
  v1::LookupCalibrationRequest request;
  request.set_porosity_2d(options.porosity);
  request.set_mean_radius_m(options.mean_radius_m);
  request.set_permeability_m2(options.permeability_m2);
  if (options.particles) request.set_particle_count(*options.particles);
  if (options.coordination) request.set_coordination_number(*options.coordination);
  request.set_limit(options.limit);

  auto stub = v1::SeepService::NewStub(OpenChannel(global));
  grpc::ClientContext ctx;
  PrepareUnaryCall(global, &ctx);
  v1::LookupCalibrationResponse response;
  if (auto status = stub->LookupCalibration(&ctx, request, &response); !status.ok()) {
    return ReportCallError(global, "calibrations lookup", status);
  }
  if (global.json) {
    std::cout << MessageToJson(response);
    return 0;
  }
  std::cout << fmt::format(
      "nearest stored calibrations to porosity {:g}, mean radius {:g} m, "
      "k = {:g} m^2\n",
      options.porosity, options.mean_radius_m, options.permeability_m2);
  std::cout << fmt::format("{:>8}  {}\n", "DISTANCE", TableHeader());
  for (const auto& n : response.nearest()) {
    std::cout << fmt::format("{:>8.4f}  {}\n", n.distance(), TableRow(n.record()));
  }
  if (response.nearest().empty()) {
    std::cout << "no converged calibration is stored yet\n";
  } else if (response.interpolated()) {
    const auto& lo = response.lower();
    const auto& hi = response.upper();
    std::cout << fmt::format(
        "interpolated a0 = {:.9g} m (log-log between k = {:g} m^2, a0 = {:.9g} m and k = {:g} "
        "m^2, a0 = {:.9g} m of job {}; setup {:.12})\n",
        response.residual_aperture_m(), lo.target_permeability_m2(), lo.residual_aperture_m(),
        hi.target_permeability_m2(), hi.residual_aperture_m(), hi.job_id(), hi.scene_sha256());
  } else {
    std::cout << fmt::format(
        "not interpolated: no two records of the nearest setup bracket k = {:g} m^2\n",
        options.permeability_m2);
  }
  return 0;
}

}  // namespace seep::client
