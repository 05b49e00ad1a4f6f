// The charts of `seep plot`, built from the service's messages with plot/svg_chart (seep_svg).
#pragma once

#include <string>
#include <vector>

#include "plot/svg_chart.h"
#include "seep/v1/job_service.pb.h"

namespace seep::client {

// Domain pressure against the axis coordinate (scatter) with the analytic pressure as a line
// where the scene has one; the centroid's x when it has none.
plot::Chart ProfileChart(const std::string& job_id, const v1::GetJobFieldsResponse& fields);

// One panel per column against time_s. Returns an empty chart and sets *error (naming the
// available columns) when a requested column does not exist.
plot::Chart SeriesChart(const std::string& job_id, const v1::TimeSeries& series,
                        const std::vector<std::string>& columns, std::string* error);

}  // namespace seep::client
