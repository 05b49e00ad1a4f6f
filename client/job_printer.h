// How the CLI shows jobs to people: a summary block, one table row, a progress line.
#pragma once

#include <map>
#include <string>

#include "seep/v1/job_service.pb.h"

namespace seep::client {

std::string StateName(v1::JobState state);  // "RUNNING"
std::string FormatJob(const v1::Job& job);  // multi-line summary with the result metrics
std::string FormatJobRow(const v1::Job& job);
std::string FormatJobTableHeader();
std::string FormatProgress(const v1::Job& job);  // one line: state, step, time, %, stage, ETA
// "2/3 inject": the current stage from 1, the stage count and the stage's name; "" for a scene
// without stages.
std::string FormatStage(const v1::Progress& progress);
// The live line of `seep watch` on a terminal: state, a bar, percent, stage, step, simulated time,
// ETA and the key metrics of the newest sample, cut to `columns` characters so that a carriage
// return redraws it in place (a wrapped line could not be redrawn).
std::string FormatProgressBar(const v1::Job& job, int columns);
std::string FormatDuration(double seconds);             // "42 s", "3m05s", "2h07m"
std::string FormatResult(const v1::JobResult& result);  // METRIC / VALUE table, sorted by name
// One "warning   ..." line per number of `metrics` below the bound its "<number>_safe_above"
// metric gives, or above the one its "<number>_safe_below" gives (a coupled job's scaled fluid
// stiffness, flow interval and step safety, docs/accuracy.md); empty when none.
std::string FormatAccuracyWarnings(const std::map<std::string, double>& metrics);
std::string FormatLabels(const v1::Job& job);                  // "k1=v1,k2=v2", sorted by key
std::string FormatJobEvent(const v1::JobHistoryEvent& event);  // one line: time, kind, message

}  // namespace seep::client
