// How the CLI shows a sweep: one progress line for the whole sweep, and the table of its swept
// parameters against chosen result metrics and job states (aligned text or CSV).
#pragma once

#include <string>
#include <vector>

#include "seep/v1/job_service.pb.h"

namespace seep::client {

// One value of a swept parameter as text: a number in its shortest exact form.
std::string SettingText(const v1::SweepSetting& setting);

// "RUNNING    54.2%  sweep s-…  6 jobs: 1 queued, 2 running, 3 succeeded, 0 failed, 0 cancelled"
// (the state and percent first, so that a line cut to a terminal's width keeps them).
std::string FormatSweepProgress(const v1::SweepStatus& sweep);

// True when every job of the sweep is SUCCEEDED, FAILED or CANCELLED.
bool SweepFinished(const v1::SweepStatus& sweep);

// The metric columns of the table: `requested` when given, else every metric any job has
// (sorted). Sets *error (naming the metrics there are) for a requested one no finished job has.
std::vector<std::string> SweepMetricColumns(const v1::SweepStatus& sweep,
                                            const std::vector<std::string>& requested,
                                            std::string* error);

// POSITION, JOB, STATE, one column per parameter, one per metric; aligned for people (metrics to
// 9 significant digits) or CSV (every number in its shortest exact form, empty where a job has
// no such metric).
std::string FormatSweepTable(const v1::SweepStatus& sweep, const std::vector<std::string>& metrics);
std::string FormatSweepCsv(const v1::SweepStatus& sweep, const std::vector<std::string>& metrics);

}  // namespace seep::client
