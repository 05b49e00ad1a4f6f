// What the coupled problems' rows say (issue 20): per problem, the run at real water and the
// cheapest run within 1 % and within 5 %, by the error against the analytic answer and against the
// same problem at real water; and the error against the fluid-to-skeleton stiffness Pi_K, the
// number every coupled job reports.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "accuracy_run.h"

namespace seep::bench {

bool IsCoupledProblem(const std::string& problem);

void PrintCoupledSummary(std::FILE* out, const std::vector<AccuracyRun>& rows);

}  // namespace seep::bench
