// Calibration codec (calibration_codec.h).
#include "calibration_codec.h"

#include <fmt/format.h>
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/util/time_util.h>

#include <algorithm>
#include <climits>
#include <map>

#include "codec/scene_codec.h"
#include "store/sha256.h"

namespace seep::service {
namespace {

using core::InvalidArgument;
using core::Result;
using core::Status;

Status CheckTags(const v1::Calibration& c) {
  if (c.tags_size() > kMaxCalibrationTags) {
    return InvalidArgument(fmt::format("calibration.tags: at most {} tags (got {})",
                                       kMaxCalibrationTags, c.tags_size()));
  }
  std::map<std::string, int> seen;
  for (int i = 0; i < c.tags_size(); ++i) {
    const std::string& tag = c.tags(i);
    if (tag.empty() || tag.size() > kMaxCalibrationTagLength) {
      return InvalidArgument(
          fmt::format("calibration.tags[{}]: must hold 1 to {} characters (got {})", i,
                      kMaxCalibrationTagLength, tag.size()));
    }
    for (const char ch : tag) {
      const auto u = static_cast<unsigned char>(ch);
      if (u < 0x21 || u == 0x7f) {
        return InvalidArgument(
            fmt::format("calibration.tags[{}]: '{}' holds a space or a control character", i, tag));
      }
    }
    if (const auto [it, fresh] = seen.emplace(tag, i); !fresh) {
      return InvalidArgument(fmt::format("calibration.tags[{}]: '{}' is already listed at index {}",
                                         i, tag, it->second));
    }
  }
  return Status::Ok();
}

// The checks every calibration passes, as submitted or as stored.
Status CheckCommon(const v1::Calibration& c) {
  if (!c.has_scene()) {
    return InvalidArgument(
        "calibration.scene: is required (packing, fluid, aperture law and a linear boundary)");
  }
  if (c.target_permeabilities_m2_size() == 0) {
    return InvalidArgument("calibration.target_permeabilities_m2: needs at least one target");
  }
  if (c.target_permeabilities_m2_size() > kMaxCalibrationTargets) {
    return InvalidArgument(
        fmt::format("calibration.target_permeabilities_m2: at most {} targets (got {})",
                    kMaxCalibrationTargets, c.target_permeabilities_m2_size()));
  }
  return CheckTags(c);
}

}  // namespace

Status CheckCalibrationRequest(const v1::Calibration& c) {
  SEEP_RETURN_IF_ERROR(CheckCommon(c));
  const bool has_packing = c.scene().packing().source_case() != v1::Packing::SOURCE_NOT_SET;
  if (!c.from_job_id().empty() && has_packing) {
    return InvalidArgument(
        "calibration.from_job_id: leave scene.packing's lattice, random and particles unset when "
        "the packing comes from an earlier job");
  }
  if (c.from_job_id().size() > 200) {
    return InvalidArgument("calibration.from_job_id: at most 200 characters");
  }
  return Status::Ok();
}

Result<core::CalibrationSpec> CalibrationFromProto(const v1::Calibration& c) {
  // from_job_id may sit next to the packing here: it is the packing's provenance once resolved.
  SEEP_RETURN_IF_ERROR(CheckCommon(c));
  if (c.scene().packing().source_case() == v1::Packing::SOURCE_NOT_SET) {
    return InvalidArgument(
        "calibration.scene.packing: one of lattice, random or particles is required (or "
        "calibration.from_job_id)");
  }
  // a0 is the result and the permeameter is always steady: decode the scene with a placeholder
  // a0 (one that satisfies a0 <= a_max, as core::ValidateCalibration does) and a steady solver,
  // so that neither produces an error the user did not make.
  v1::Scene probe = c.scene();
  const double cap = probe.aperture().max_aperture_m();
  probe.mutable_aperture()->set_residual_aperture_m(cap > 0.0 ? cap : 1.0);
  probe.mutable_solver()->Clear();
  probe.mutable_solver()->set_kind(v1::SOLVER_KIND_STEADY);
  auto scene = SceneFromProto(probe);
  if (!scene.ok()) return Status(scene.status().code(), "calibration." + scene.status().message());

  core::CalibrationSpec spec;
  spec.scene = std::move(*scene);
  spec.scene.aperture.residual_aperture_m = 0.0;
  spec.stress.uniform_normal_force_n = c.stress().uniform_normal_force_n();
  for (const v1::ContactForce& f : c.stress().contact_forces()) {
    spec.stress.contact_forces.push_back({f.particle_i(), f.particle_j(), f.normal_force_n()});
  }
  spec.target_permeabilities_m2.assign(c.target_permeabilities_m2().begin(),
                                       c.target_permeabilities_m2().end());
  spec.tolerance = c.tolerance() == 0.0 ? kDefaultCalibrationTolerance : c.tolerance();
  spec.max_iterations =
      c.max_iterations() == 0
          ? kDefaultCalibrationIterations
          : static_cast<int>(std::min<std::uint32_t>(c.max_iterations(), INT_MAX));
  SEEP_RETURN_IF_ERROR(core::ValidateCalibration(spec));
  return spec;
}

Status ResolvePackingFrom(const JobRecord& earlier, v1::Calibration* calibration) {
  v1::Packing packing;
  if (earlier.kind == JobKind::kCalibration) {
    v1::Calibration stored;
    if (!stored.ParseFromString(earlier.scene)) {
      return core::FailedPrecondition(fmt::format(
          "calibration.from_job_id: the stored calibration of job {} does not parse", earlier.id));
    }
    packing = stored.scene().packing();
  } else {
    v1::Scene stored;
    if (!stored.ParseFromString(earlier.scene)) {
      return core::FailedPrecondition(fmt::format(
          "calibration.from_job_id: the stored scene of job {} does not parse", earlier.id));
    }
    packing = stored.packing();
  }
  v1::Packing* target = calibration->mutable_scene()->mutable_packing();
  const double gap = target->contact_gap_m();
  *target = std::move(packing);
  if (gap > 0.0) target->set_contact_gap_m(gap);
  return Status::Ok();
}

std::string CalibrationSetupSha256(const v1::Calibration& calibration) {
  v1::Calibration setup;
  *setup.mutable_scene() = calibration.scene();
  setup.mutable_scene()->clear_name();
  setup.mutable_scene()->clear_solver();
  setup.mutable_scene()->mutable_aperture()->clear_residual_aperture_m();
  *setup.mutable_stress() = calibration.stress();
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream stream(&bytes);
    google::protobuf::io::CodedOutputStream coded(&stream);
    coded.SetSerializationDeterministic(true);
    setup.SerializeToCodedStream(&coded);
  }
  return HexSha256(bytes);
}

void CalibrationRecordToProto(const StoredCalibration& stored, v1::CalibrationRecord* out) {
  const core::CalibrationRecord& r = stored.record;
  out->set_job_id(stored.job_id);
  out->set_target_index(static_cast<std::uint32_t>(r.target_index));
  out->set_target_permeability_m2(r.target_permeability_m2);
  out->set_residual_aperture_m(r.residual_aperture_m);
  out->set_permeability_m2(r.permeability_m2);
  out->set_relative_error(r.relative_error);
  out->set_converged(r.converged);
  out->set_tolerance(stored.tolerance);
  out->set_iterations(static_cast<std::uint32_t>(r.iterations));
  out->set_corrections(static_cast<std::uint32_t>(r.corrections));
  out->set_first_guess_residual_aperture_m(r.first_guess_residual_aperture_m);
  out->set_first_guess_permeability_m2(r.first_guess_permeability_m2);
  out->set_first_guess_relative_error(r.first_guess_relative_error);
  auto* p = out->mutable_packing();
  p->set_particle_count(r.packing.particle_count);
  p->set_contact_count(r.packing.contact_count);
  p->set_domain_count(r.packing.domain_count);
  p->set_pipe_count(r.packing.pipe_count);
  p->set_porosity_2d(r.packing.porosity_2d);
  p->set_mean_radius_m(r.packing.mean_radius_m);
  p->set_radius_std_dev_m(r.packing.radius_std_dev_m);
  p->set_min_radius_m(r.packing.min_radius_m);
  p->set_max_radius_m(r.packing.max_radius_m);
  p->set_coordination_number(r.packing.coordination_number);
  out->mutable_fluid()->set_viscosity_pa_s(r.fluid.viscosity_pa_s);
  out->mutable_fluid()->set_bulk_modulus_pa(r.fluid.bulk_modulus_pa);
  auto* a = out->mutable_aperture();
  a->set_residual_aperture_m(r.residual_aperture_m);
  a->set_reference_force_n(r.aperture.reference_force_n);
  a->set_gap_multiplier(r.aperture.gap_multiplier);
  a->set_max_aperture_m(r.aperture.max_aperture_m);
  auto* s = out->mutable_stress();
  s->set_uniform_normal_force_n(r.stress.uniform_normal_force_n);
  s->set_listed_contact_forces(r.stress.listed_contact_forces);
  s->set_pipes_in_compression(r.stress.pipes_in_compression);
  s->set_pipes_closed_unloaded(r.stress.pipes_closed_unloaded);
  s->set_pipes_open(r.stress.pipes_open);
  s->set_pipes_capped(r.stress.pipes_capped);
  s->set_min_normal_force_n(r.stress.min_normal_force_n);
  s->set_mean_normal_force_n(r.stress.mean_normal_force_n);
  s->set_max_normal_force_n(r.stress.max_normal_force_n);
  s->set_aperture_proportional_to_a0(r.stress.aperture_proportional_to_a0);
  out->set_flow_axis(r.flow_axis == core::FlowAxis::kX ? v1::FLOW_AXIS_X : v1::FLOW_AXIS_Y);
  out->set_pressure_drop_pa(r.pressure_drop_pa);
  out->set_sample_length_m(r.sample_length_m);
  out->set_sample_width_m(r.sample_width_m);
  out->set_scene_sha256(stored.scene_sha256);
  out->set_build_id(stored.build_id);
  *out->mutable_created_at() =
      google::protobuf::util::TimeUtil::MillisecondsToTimestamp(stored.created_at_ms);
  for (const std::string& tag : stored.tags) out->add_tags(tag);
}

}  // namespace seep::service
