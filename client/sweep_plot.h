// The chart of `seep sweep plot`: a result metric against one swept parameter, one line per
// combination of the other parameters' values, built with plot/svg_chart (seep_svg).
#pragma once

#include <string>

#include "plot/svg_chart.h"
#include "seep/v1/job_service.pb.h"

namespace seep::client {

// How `seep sweep plot` draws: which metric against which parameter, on which scales.
struct SweepChartRequest {
  std::string x_path;
  std::string y_metric;
  bool log_x = false;  // log10 axes (points <= 0 are left out there)
  bool log_y = false;
};

// The SUCCEEDED jobs' metric against the parameter. Returns an empty chart and sets *error when
// the parameter is not a numeric one of the sweep, or no succeeded job has the metric.
plot::Chart SweepChart(const v1::SweepStatus& sweep, const SweepChartRequest& request,
                       std::string* error);

}  // namespace seep::client
