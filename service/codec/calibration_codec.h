// seep.v1.Calibration <-> core::CalibrationSpec, and stored calibration records -> the wire
// CalibrationRecord. Wire checks here (a missing scene, a packing given twice, tags); physical
// ranges in core::ValidateCalibration. Every error names the field by its path in the request
// ("calibration.target_permeabilities_m2[2]: must be a finite number > 0 (got -1)").
#pragma once

#include <string>

#include "seep/core/calibration/calibration_spec.h"
#include "seep/core/status.h"
#include "seep/v1/calibration.pb.h"
#include "store/job_record.h"
#include "store/stored_calibration.h"

namespace seep::service {

// Defaults for the zero values of the wire (proto3 cannot tell unset from 0).
inline constexpr double kDefaultCalibrationTolerance = 1e-6;
inline constexpr int kDefaultCalibrationIterations = 30;
inline constexpr int kMaxCalibrationTags = 32;
inline constexpr int kMaxCalibrationTargets = 1000;
inline constexpr std::size_t kMaxCalibrationTagLength = 64;

// Decodes and validates a calibration whose packing is set (from_job_id already resolved by
// ResolvePackingFrom, or never set). A from_job_id next to the packing is the packing's
// provenance here, not an error: CheckCalibrationRequest is the check of a submitted request.
core::Result<core::CalibrationSpec> CalibrationFromProto(const v1::Calibration& calibration);

// Checks the fields that need no packing: the calibration as submitted, before from_job_id is
// resolved (so that a bad request fails before the store is read).
core::Status CheckCalibrationRequest(const v1::Calibration& calibration);

// Copies the packing of an earlier job (its scene's, or its calibration's) into
// calibration.scene.packing; a contact_gap_m > 0 in the calibration is kept. FAILED_PRECONDITION
// when the earlier job's stored input does not parse.
core::Status ResolvePackingFrom(const JobRecord& earlier, v1::Calibration* calibration);

// SHA-256 (hex) of the physical setup: scene (packing, fluid, aperture law without a0, boundary)
// and stress state, serialized deterministically; name, solver, targets, tolerance and tags are
// left out, so every sweep of one setup shares it.
std::string CalibrationSetupSha256(const v1::Calibration& calibration);

void CalibrationRecordToProto(const StoredCalibration& stored, v1::CalibrationRecord* out);

}  // namespace seep::service
