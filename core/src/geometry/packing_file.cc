#include "seep/core/geometry/packing_file.h"

#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

namespace seep::core {
namespace {

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string Where(std::string_view source, std::size_t line) {
  return "packing file '" + std::string(source) + "' line " + std::to_string(line) + ": ";
}

// Splits `line` into blank-separated fields; returns how many there were (at most `out.size()` are
// stored, the count keeps going so that "too many fields" can be reported).
std::size_t SplitFields(std::string_view line, std::array<std::string_view, 3>& out) {
  std::size_t count = 0;
  std::size_t pos = 0;
  while (pos < line.size()) {
    while (pos < line.size() && IsBlank(line[pos])) ++pos;
    if (pos >= line.size()) break;
    const std::size_t start = pos;
    while (pos < line.size() && !IsBlank(line[pos])) ++pos;
    if (count < out.size()) out[count] = line.substr(start, pos - start);
    ++count;
  }
  return count;
}

Status ParseNumber(std::string_view field, const char* name, std::string_view source,
                   std::size_t line, double* value) {
  const char* first = field.data();
  const char* last = field.data() + field.size();
  if (first != last && *first == '+') ++first;  // from_chars rejects a leading '+'
  const auto [ptr, ec] = std::from_chars(first, last, *value);
  if (ec != std::errc() || ptr != last) {
    return InvalidArgument(Where(source, line) + name + " is not a number (got '" +
                           std::string(field) + "')");
  }
  if (!std::isfinite(*value)) {
    return InvalidArgument(Where(source, line) + name + " must be finite (got '" +
                           std::string(field) + "')");
  }
  return Status::Ok();
}

}  // namespace

Result<Packing> ParsePackingText(std::string_view text, std::string_view source_name) {
  Packing packing;
  std::size_t line_number = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;

    const std::size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    std::array<std::string_view, 3> fields;
    const std::size_t count = SplitFields(line, fields);
    if (count == 0) continue;
    if (count != 3) {
      return InvalidArgument(Where(source_name, line_number) +
                             "expected 3 fields 'x y radius', got " + std::to_string(count));
    }
    double x = 0.0;
    double y = 0.0;
    double r = 0.0;
    SEEP_RETURN_IF_ERROR(ParseNumber(fields[0], "x", source_name, line_number, &x));
    SEEP_RETURN_IF_ERROR(ParseNumber(fields[1], "y", source_name, line_number, &y));
    SEEP_RETURN_IF_ERROR(ParseNumber(fields[2], "radius", source_name, line_number, &r));
    if (!(r > 0.0)) {
      return InvalidArgument(Where(source_name, line_number) + "radius must be > 0 (got " +
                             std::string(fields[2]) + ")");
    }
    packing.Add(x, y, r);
  }
  if (packing.size() == 0) {
    return InvalidArgument("packing file '" + std::string(source_name) +
                           "': no particles (only blank or comment lines)");
  }
  return packing;
}

Result<Packing> LoadPackingFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return NotFound("packing file '" + path + "': cannot be opened");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return InvalidArgument("packing file '" + path + "': read error");
  return ParsePackingText(buffer.str(), path);
}

}  // namespace seep::core
