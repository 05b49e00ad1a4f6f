// The Pareto front of a set of runs in (wall time, error): the runs that no other run beats on
// both at once. They are what a user should choose from; every other run costs more for the same
// accuracy or is less accurate for the same cost.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "accuracy_run.h"

namespace seep::bench {

// Indices into `rows` of the front of the runs of `problem` that produced a finite error, sorted
// by wall time (so the errors fall along it). Ties in both keep the first run. resolution >= 0
// restricts it to the runs at that resolution.
std::vector<std::size_t> ParetoFront(const std::vector<AccuracyRun>& rows,
                                     const std::string& problem, int resolution = -1);

// The problems of `rows` in order of first appearance.
std::vector<std::string> Problems(const std::vector<AccuracyRun>& rows);

}  // namespace seep::bench
