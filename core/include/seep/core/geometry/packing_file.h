// Reading a packing from a text file.
//
// Format: one disk per line, "x y radius" separated by spaces or tabs. Blank lines are skipped and
// '#' starts a comment that runs to the end of the line (whole-line or trailing). Particle ids are
// assigned in file order, starting at 0.
#pragma once

#include <string>
#include <string_view>

#include "seep/core/geometry/packing.h"
#include "seep/core/status.h"

namespace seep::core {

// NotFound when the file cannot be opened. InvalidArgument, naming the file and the 1-based line,
// for: a field that is not a number, a value that is not finite, radius <= 0, a line without
// exactly three fields, and a file with no particles, e.g.
//   "packing file 'bed.txt' line 7: radius must be > 0 (got -1)".
Result<Packing> LoadPackingFile(const std::string& path);

// The same parser over text already in memory; `source_name` stands in for the file name in
// messages.
Result<Packing> ParsePackingText(std::string_view text, std::string_view source_name);

}  // namespace seep::core
