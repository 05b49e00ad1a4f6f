// The seep CLI's calibration commands: submit a calibration, list the stored records, look one
// up. Exit codes as the other commands (commands.h).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "commands.h"

namespace seep::client {

struct CalibrateOptions {
  std::string file;  // a seep.v1.Calibration, .textproto or .json
  std::string name;
  std::string request_id;
  std::string from_job;             // overrides the file's from_job_id
  std::vector<std::string> tags;    // added to the file's tags
  std::vector<std::string> labels;  // KEY=VALUE labels of the job
  bool watch = false;
};

// Submits a calibration job (SubmitJob with `calibration` set).
int Calibrate(const GlobalOptions& global, const CalibrateOptions& options);

struct CalibrationListOptions {
  std::optional<double> k_min, k_max;  // m^2, on the target permeability
  std::optional<double> porosity_min, porosity_max;
  std::optional<double> radius_min, radius_max;  // m, on the mean radius
  std::vector<std::string> tags;                 // every one must be present
  std::string after, before;                     // RFC 3339 times, e.g. 2026-11-23T00:00:00Z
  std::string job;
  unsigned limit = 50;
  bool csv = false;
};

// Prints the stored records, newest first: a table, --csv or --json.
int ListCalibrations(const GlobalOptions& global, const CalibrationListOptions& options);

struct CalibrationLookupOptions {
  double porosity = 0.0;
  double mean_radius_m = 0.0;
  double permeability_m2 = 0.0;
  std::optional<unsigned long long> particles;
  std::optional<double> coordination;
  unsigned limit = 5;
};

// The nearest stored records and, where records of one setup bracket k, the interpolated a0.
int LookupCalibration(const GlobalOptions& global, const CalibrationLookupOptions& options);

}  // namespace seep::client
