// The chart of `seep sweep plot`: a result metric against one swept parameter, one line per
// combination of the other parameters' values, built with plot/svg_chart (seep_svg).
#pragma once

#include <string>

#include "plot/svg_chart.h"
#include "seep/v1/job_service.pb.h"

namespace seep::client {

// The SUCCEEDED jobs' metric y_metric against parameter x_path. Returns an empty chart and sets
// *error when x_path is not a numeric parameter of the sweep, or no succeeded job has y_metric.
plot::Chart SweepChart(const v1::SweepStatus& sweep, const std::string& x_path,
                       const std::string& y_metric, std::string* error);

}  // namespace seep::client
