// The accuracy bench's text outputs: the CSV file (one row per run, a header line) and the
// tables printed to stdout.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "accuracy_run.h"
#include "seep/core/status.h"

namespace seep::bench {

core::Status WriteCsv(const std::string& path, const std::vector<AccuracyRun>& rows);

// One line per run, aligned columns, to `out`.
void PrintTable(std::FILE* out, const std::vector<AccuracyRun>& rows,
                const std::vector<std::size_t>& which);

}  // namespace seep::bench
