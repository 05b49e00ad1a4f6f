// How the CLI shows jobs to people: a summary block, one table row, a progress line.
#pragma once

#include <string>

#include "seep/v1/job_service.pb.h"

namespace seep::client {

std::string StateName(v1::JobState state);  // "RUNNING"
std::string FormatJob(const v1::Job& job);  // multi-line summary with the result metrics
std::string FormatJobRow(const v1::Job& job);
std::string FormatJobTableHeader();
std::string FormatProgress(const v1::Job& job);         // one line: state, step, time, %, ETA
std::string FormatResult(const v1::JobResult& result);  // METRIC / VALUE table, sorted by name

}  // namespace seep::client
