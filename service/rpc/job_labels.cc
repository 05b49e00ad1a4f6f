#include "rpc/job_labels.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

namespace seep::service {
namespace {

bool IsLowerOrDigit(char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); }

bool IsKeyCharacter(char c) { return IsLowerOrDigit(c) || c == '-' || c == '_' || c == '.'; }

bool IsValueCharacter(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 ||
         std::string_view("-_.:/@+").find(c) != std::string_view::npos;
}

// A key as it can be printed in an error: control and non-ASCII bytes escaped.
std::string Printable(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u >= 0x7f || c == '"' || c == '\\') {
      out += fmt::format("\\x{:02x}", u);
    } else {
      out += c;
    }
  }
  return out;
}

std::string KeyProblem(const std::string& key) {
  if (key.empty() || key.size() > kMaxLabelKeyLength) {
    return fmt::format("the key must hold 1 to {} characters (got {})", kMaxLabelKeyLength,
                       key.size());
  }
  if (!(key.front() >= 'a' && key.front() <= 'z') || !IsLowerOrDigit(key.back()) ||
      !std::all_of(key.begin(), key.end(), IsKeyCharacter)) {
    return "the key must be lower-case letters, digits, '-', '_' and '.', starting with a letter "
           "and ending with a letter or digit";
  }
  return {};
}

std::string ValueProblem(const std::string& value) {
  if (value.size() > kMaxLabelValueLength) {
    return fmt::format("the value must hold at most {} characters (got {})", kMaxLabelValueLength,
                       value.size());
  }
  if (!std::all_of(value.begin(), value.end(), IsValueCharacter)) {
    return fmt::format("the value '{}' may hold only letters, digits and - _ . : / @ +",
                       Printable(value));
  }
  return {};
}

}  // namespace

core::Result<std::vector<std::pair<std::string, std::string>>> CheckLabels(
    const google::protobuf::Map<std::string, std::string>& labels) {
  if (labels.size() > kMaxLabels) {
    return core::InvalidArgument(
        fmt::format("labels: at most {} per job (got {})", kMaxLabels, labels.size()));
  }
  std::vector<std::pair<std::string, std::string>> sorted(labels.begin(), labels.end());
  std::sort(sorted.begin(), sorted.end());
  for (const auto& [key, value] : sorted) {
    std::string problem = KeyProblem(key);
    if (problem.empty()) problem = ValueProblem(value);
    if (!problem.empty()) {
      return core::InvalidArgument(fmt::format("labels[\"{}\"]: {}", Printable(key), problem));
    }
  }
  return sorted;
}

}  // namespace seep::service
