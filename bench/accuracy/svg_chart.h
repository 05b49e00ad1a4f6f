// The error-versus-wall-time chart of the accuracy bench as a hand-written SVG: one log-log panel
// per problem, one marker shape and colour per solver (and storage), the Pareto front drawn as a
// line through its runs, and a dashed line at 1% error on the transient panels. A last panel shows
// the last diffusion problem at its finest resolution alone (resolution fixed by the packing).
#pragma once

#include <string>
#include <vector>

#include "accuracy_run.h"
#include "seep/core/status.h"

namespace seep::bench {

core::Status WriteSvgChart(const std::string& path, const std::vector<AccuracyRun>& rows);

}  // namespace seep::bench
