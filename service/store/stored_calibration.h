// What the store keeps of a calibration: core's CalibrationRecord (plain data) with where it came
// from, and the filters and probes the calibration queries take. No SQL and no protobuf here.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "seep/core/calibration/calibration_record.h"

namespace seep::service {

struct StoredCalibration {
  std::int64_t row_id = 0;  // set when read back; newer records have larger ids
  std::string job_id;
  core::CalibrationRecord record;
  double tolerance = 0.0;
  // SHA-256 (hex) of the physical setup (calibration_codec.h): equal for every record of one
  // scene, fluid, aperture law and stress state.
  std::string scene_sha256;
  std::string build_id;
  std::int64_t created_at_ms = 0;
  std::vector<std::string> tags;  // the job's tags, sorted
};

// Which records ListCalibrations returns; unset members do not filter. Ranges are inclusive,
// except created_before (created_at_ms < created_before_ms).
struct CalibrationFilter {
  std::optional<double> min_permeability_m2;  // on the target permeability
  std::optional<double> max_permeability_m2;
  std::optional<double> min_porosity;
  std::optional<double> max_porosity;
  std::optional<double> min_mean_radius_m;
  std::optional<double> max_mean_radius_m;
  std::vector<std::string> tags;  // every one must be present
  std::optional<std::int64_t> created_after_ms;
  std::optional<std::int64_t> created_before_ms;
  std::string job_id;  // empty = every job
};

struct CalibrationPage {
  std::vector<StoredCalibration> records;  // newest first
  std::optional<std::int64_t> next_cursor;
};

// A packing description and a target permeability to look up.
struct CalibrationProbe {
  double porosity_2d = 0.0;
  double mean_radius_m = 0.0;
  std::optional<double> particle_count;
  std::optional<double> coordination_number;
  double permeability_m2 = 0.0;
};

struct CalibrationNeighbour {
  StoredCalibration calibration;
  double distance = 0.0;  // CalibrationDistance
};

}  // namespace seep::service
