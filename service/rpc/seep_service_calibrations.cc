// SeepServiceImpl: the calibration half of SubmitJob, ListCalibrations and LookupCalibration.
// Handlers only decode, read the store and encode; calibrations run on the workers.
#include <fmt/format.h>
#include <google/protobuf/util/time_util.h>

#include <cmath>
#include <exception>

#include "codec/calibration_codec.h"
#include "rpc/handler.h"
#include "rpc/page_token.h"
#include "rpc/seep_service.h"
#include "store/calibration_lookup.h"

namespace seep::service {
namespace {

constexpr std::uint32_t kDefaultNeighbours = 5;
constexpr std::uint32_t kMaxNeighbours = 100;

grpc::Status Invalid(std::string message) {
  return {grpc::StatusCode::INVALID_ARGUMENT, std::move(message)};
}

std::int64_t ToMs(const google::protobuf::Timestamp& t) {
  return google::protobuf::util::TimeUtil::TimestampToMilliseconds(t);
}

grpc::Status ListCalibrationsFrom(JobStore& store, const v1::ListCalibrationsRequest& req,
                                  v1::ListCalibrationsResponse* resp) {
  auto cursor = DecodePageToken(req.page_token(), req, "ListCalibrations");
  if (!cursor.ok()) return ToGrpcStatus(cursor.status());
  CalibrationFilter filter;
  struct Bound {
    bool set;
    double value;
    const char* field;
    std::optional<double>* into;
  };
  for (const Bound& b : {
           Bound{req.has_min_permeability_m2(), req.min_permeability_m2(), "min_permeability_m2",
                 &filter.min_permeability_m2},
           Bound{req.has_max_permeability_m2(), req.max_permeability_m2(), "max_permeability_m2",
                 &filter.max_permeability_m2},
           Bound{req.has_min_porosity(), req.min_porosity(), "min_porosity", &filter.min_porosity},
           Bound{req.has_max_porosity(), req.max_porosity(), "max_porosity", &filter.max_porosity},
           Bound{req.has_min_mean_radius_m(), req.min_mean_radius_m(), "min_mean_radius_m",
                 &filter.min_mean_radius_m},
           Bound{req.has_max_mean_radius_m(), req.max_mean_radius_m(), "max_mean_radius_m",
                 &filter.max_mean_radius_m},
       }) {
    if (!b.set) continue;
    if (!std::isfinite(b.value)) {
      return Invalid(fmt::format("{}: must be a finite number (got {})", b.field, b.value));
    }
    *b.into = b.value;
  }
  if (req.tags_size() > kMaxCalibrationTags) {
    return Invalid(fmt::format("tags: at most {} (got {})", kMaxCalibrationTags, req.tags_size()));
  }
  for (int i = 0; i < req.tags_size(); ++i) {
    if (req.tags(i).empty() || req.tags(i).size() > kMaxCalibrationTagLength) {
      return Invalid(
          fmt::format("tags[{}]: must hold 1 to {} characters", i, kMaxCalibrationTagLength));
    }
    filter.tags.push_back(req.tags(i));
  }
  if (req.has_created_after()) filter.created_after_ms = ToMs(req.created_after());
  if (req.has_created_before()) filter.created_before_ms = ToMs(req.created_before());
  if (core::Status s = CheckIdLength(req.job_id(), "job_id"); !s.ok()) return ToGrpcStatus(s);
  filter.job_id = req.job_id();
  auto page = store.ListCalibrations(PageSize(req.page_size()), *cursor, filter);
  if (!page.ok()) return ToGrpcStatus(page.status());
  for (const StoredCalibration& c : page->records) {
    CalibrationRecordToProto(c, resp->add_records());
  }
  if (page->next_cursor) resp->set_next_page_token(EncodePageToken(*page->next_cursor, req));
  return grpc::Status::OK;
}

grpc::Status LookupCalibrationFrom(JobStore& store, const v1::LookupCalibrationRequest& req,
                                   v1::LookupCalibrationResponse* resp) {
  CalibrationProbe probe;
  probe.porosity_2d = req.porosity_2d();
  probe.mean_radius_m = req.mean_radius_m();
  probe.permeability_m2 = req.permeability_m2();
  if (!(probe.porosity_2d > 0.0 && probe.porosity_2d < 1.0)) {
    return Invalid(fmt::format("porosity_2d: must lie in (0, 1) (got {})", probe.porosity_2d));
  }
  if (!(probe.mean_radius_m > 0.0) || !std::isfinite(probe.mean_radius_m)) {
    return Invalid(
        fmt::format("mean_radius_m: must be a finite number > 0 (got {})", probe.mean_radius_m));
  }
  if (!(probe.permeability_m2 > 0.0) || !std::isfinite(probe.permeability_m2)) {
    return Invalid(fmt::format("permeability_m2: must be a finite number > 0 (got {})",
                               probe.permeability_m2));
  }
  if (req.has_particle_count()) {
    if (req.particle_count() == 0) return Invalid("particle_count: must be > 0 when set");
    probe.particle_count = static_cast<double>(req.particle_count());
  }
  if (req.has_coordination_number()) {
    if (!(req.coordination_number() > 0.0) || !std::isfinite(req.coordination_number())) {
      return Invalid(
          fmt::format("coordination_number: must be a finite number > 0 when set (got {})",
                      req.coordination_number()));
    }
    probe.coordination_number = req.coordination_number();
  }
  const std::uint32_t limit =
      req.limit() == 0 ? kDefaultNeighbours : std::min(req.limit(), kMaxNeighbours);
  auto nearest = store.NearestCalibrations(probe, limit);
  if (!nearest.ok()) return ToGrpcStatus(nearest.status());
  for (const CalibrationNeighbour& n : *nearest) {
    auto* out = resp->add_nearest();
    CalibrationRecordToProto(n.calibration, out->mutable_record());
    out->set_distance(n.distance);
  }
  if (nearest->empty()) return grpc::Status::OK;
  // Interpolate only within the nearest record's setup: another packing, fluid, aperture law or
  // stress state has another a0(k) curve.
  auto same_setup = store.CalibrationsOfSetup(nearest->front().calibration.scene_sha256);
  if (!same_setup.ok()) return ToGrpcStatus(same_setup.status());
  if (auto interpolated = InterpolateApertureLogLog(*same_setup, probe.permeability_m2)) {
    resp->set_interpolated(true);
    resp->set_residual_aperture_m(interpolated->residual_aperture_m);
    CalibrationRecordToProto(interpolated->lower, resp->mutable_lower());
    CalibrationRecordToProto(interpolated->upper, resp->mutable_upper());
  }
  return grpc::Status::OK;
}

}  // namespace

core::Result<SeepServiceImpl::PreparedCalibration> SeepServiceImpl::PrepareCalibrationJob(
    const v1::Calibration& calibration) {
  // Measured before decoding, so an oversized calibration costs no decode and leaves no trace.
  if (const std::size_t bytes = calibration.ByteSizeLong(); bytes > guards_.max_scene_bytes) {
    return core::InvalidArgument(
        fmt::format("calibration: {} bytes exceed the limit of {} (seepd --max-scene-bytes)", bytes,
                    guards_.max_scene_bytes));
  }
  SEEP_RETURN_IF_ERROR(CheckCalibrationRequest(calibration));
  v1::Calibration resolved = calibration;
  SEEP_RETURN_IF_ERROR(CheckNameLength(calibration.name(), "calibration.name"));
  SEEP_RETURN_IF_ERROR(CheckIdLength(calibration.from_job_id(), "calibration.from_job_id"));
  if (!calibration.from_job_id().empty()) {
    auto earlier = store_.Get(calibration.from_job_id());
    if (!earlier.ok()) {
      return core::Status(earlier.status().code(),
                          "calibration.from_job_id: " + earlier.status().message());
    }
    SEEP_RETURN_IF_ERROR(ResolvePackingFrom(*earlier, &resolved));
    if (const std::size_t bytes = resolved.ByteSizeLong(); bytes > guards_.max_scene_bytes) {
      return core::InvalidArgument(fmt::format(
          "calibration.from_job_id: with the packing of job {} the calibration holds {} bytes, "
          "over the limit of {} (seepd --max-scene-bytes)",
          calibration.from_job_id(), bytes, guards_.max_scene_bytes));
    }
  }
  // Validate fully before anything is stored: a bad calibration leaves no trace.
  SEEP_RETURN_IF_ERROR(CalibrationFromProto(resolved).status());
  PreparedCalibration prepared;
  prepared.name = resolved.name();
  if (!resolved.SerializeToString(&prepared.bytes)) {
    return core::Internal("calibration: could not serialize");
  }
  return prepared;
}

grpc::Status SeepServiceImpl::ListCalibrations(grpc::ServerContext* ctx,
                                               const v1::ListCalibrationsRequest* req,
                                               v1::ListCalibrationsResponse* resp) {
  return Guarded(ctx, "ListCalibrations", [&] { return ListCalibrationsFrom(store_, *req, resp); });
}

grpc::Status SeepServiceImpl::LookupCalibration(grpc::ServerContext* ctx,
                                                const v1::LookupCalibrationRequest* req,
                                                v1::LookupCalibrationResponse* resp) {
  return Guarded(ctx, "LookupCalibration",
                 [&] { return LookupCalibrationFrom(store_, *req, resp); });
}

}  // namespace seep::service
