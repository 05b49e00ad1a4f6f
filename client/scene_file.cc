// Reading scene and calibration files, and pointing errors at the line of the field (scene_file.h).
#include "scene_file.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

namespace seep::client {
namespace {

class CollectFirstError : public google::protobuf::io::ErrorCollector {
 public:
  void AddError(int line, google::protobuf::io::ColumnNumber column,
                const std::string& message) override {
    if (first_.empty()) {
      first_ = std::to_string(line + 1) + ":" + std::to_string(column + 1) + ": " + message;
    }
  }
  const std::string& first() const { return first_; }

 private:
  std::string first_;
};

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// One step of a field path: "radius_m" or "target_permeabilities_m2[3]" (index -1 when none).
struct PathStep {
  std::string name;
  int index = -1;
};

std::vector<PathStep> SplitFieldPath(const std::string& path) {
  std::vector<PathStep> steps;
  std::stringstream in(path);
  std::string part;
  while (std::getline(in, part, '.')) {
    PathStep step;
    const auto bracket = part.find('[');
    step.name = part.substr(0, bracket);
    if (bracket != std::string::npos) step.index = std::atoi(part.c_str() + bracket + 1);
    if (!step.name.empty()) steps.push_back(step);
  }
  return steps;
}

// Line and column (1-based) of a byte offset in the text.
std::pair<int, int> LineAndColumn(const std::string& text, std::size_t offset) {
  offset = std::min(offset, text.size());
  const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + offset, '\n'));
  const auto line_start = text.rfind('\n', offset == 0 ? 0 : offset - 1);
  const std::size_t column =
      line_start == std::string::npos || offset == 0 ? offset + 1 : offset - line_start;
  return {line, static_cast<int>(column)};
}

// protobuf's JSON parser reports a syntax error as "what\n<up to 20 bytes either side>\n   ^"
// without an offset: finding the quoted text in the file gives the offset back.
bool LocateJsonSyntaxError(const std::string& text, const std::string& error, std::string* what,
                           std::size_t* offset) {
  const auto first_newline = error.find('\n');
  const auto last_newline = error.rfind('\n');
  if (first_newline == std::string::npos || last_newline == first_newline) return false;
  const std::string segment = error.substr(first_newline + 1, last_newline - first_newline - 1);
  const std::string caret = error.substr(last_newline + 1);
  const auto caret_column = caret.find('^');
  if (segment.empty() || caret_column == std::string::npos) return false;
  const auto found = text.find(segment);
  if (found == std::string::npos) return false;
  *what = error.substr(0, first_newline);
  *offset = found + caret_column;
  return true;
}

}  // namespace

std::string MessageFile::Load(const std::string& path, google::protobuf::Message* message,
                              const std::string& what) {
  path_ = path;
  json_ = EndsWith(path, ".json");
  descriptor_ = message->GetDescriptor();
  std::ifstream in(path, std::ios::binary);
  if (!in) return path + ": cannot open the " + what + " file";
  std::stringstream buffer;
  buffer << in.rdbuf();
  text_ = buffer.str();

  if (json_) {
    google::protobuf::util::JsonParseOptions options;
    options.ignore_unknown_fields = false;
    const auto status = google::protobuf::util::JsonStringToMessage(text_, message, options);
    if (status.ok()) return {};
    const std::string error(status.message());
    // Syntax: the quoted context locates the byte.
    std::string syntax;
    std::size_t offset = 0;
    if (LocateJsonSyntaxError(text_, error, &syntax, &offset)) {
      const auto [line, column] = LineAndColumn(text_, offset);
      return path + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + syntax;
    }
    // A bad value or an unknown field: "(fluid.viscosity_pa_s): invalid value ..." or
    // "(fluid) nope: Cannot find field." name the field path; find its key in the text.
    std::smatch m;
    std::string field_path;
    std::string reason = error;
    if (std::regex_search(error, m, std::regex(R"(^\(([^)]*)\)\s*([A-Za-z0-9_]+): (.*)$)"))) {
      field_path = m[1].str().empty() ? m[2].str() : m[1].str() + "." + m[2].str();
      reason = m[3].str() == "Cannot find field." ? "no such field" : m[3].str();
    } else if (std::regex_search(error, m, std::regex(R"(^\(([^)]*)\):\s*(.*)$)"))) {
      field_path = m[1];
      reason = m[2];
    } else if (std::regex_search(error, m,
                                 std::regex(R"(^([A-Za-z0-9_]+): Cannot find field\.$)"))) {
      field_path = m[1];  // a top-level unknown field has no "(parent)"
      reason = "no such field";
    }
    if (field_path.empty()) return path + ": " + error;
    const int line = LineOfInJson(field_path);
    return path + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + what + "." +
           field_path + ": " + reason;
  }
  google::protobuf::TextFormat::Parser parser;
  CollectFirstError errors;
  parser.RecordErrorsTo(&errors);
  locations_ = std::make_unique<google::protobuf::TextFormat::ParseInfoTree>();
  parser.WriteLocationsTo(locations_.get());
  if (!parser.ParseFromString(text_, message)) {
    return path + ":" + (errors.first().empty() ? std::string("parse error") : errors.first());
  }
  return {};
}

int MessageFile::LineOf(const std::string& field_path) const {
  if (text_.empty()) return 0;
  return json_ ? LineOfInJson(field_path) : LineOfInText(field_path);
}

int MessageFile::LineOfInText(const std::string& field_path) const {
  if (!locations_) return 0;
  int line = 0;
  const google::protobuf::Descriptor* descriptor = descriptor_;
  const google::protobuf::TextFormat::ParseInfoTree* tree = locations_.get();
  for (const PathStep& step : SplitFieldPath(field_path)) {
    if (descriptor == nullptr || tree == nullptr) break;
    const google::protobuf::FieldDescriptor* field = descriptor->FindFieldByName(step.name);
    if (field == nullptr) break;
    // A list written as `name: [a, b]` has one location for all its values: fall back to it.
    int index = field->is_repeated() ? std::max(step.index, 0) : -1;
    auto location = tree->GetLocation(field, index);
    if (location.line < 0 && index > 0) location = tree->GetLocation(field, index = 0);
    if (location.line < 0) break;
    line = location.line + 1;
    if (field->message_type() == nullptr) break;
    tree = tree->GetTreeForNested(field, index);
    descriptor = field->message_type();
  }
  return line;
}

int MessageFile::LineOfInJson(const std::string& field_path) const {
  // JSON has no location info in protobuf's parser: follow the path's keys through the text, each
  // one searched after its parent's. Either spelling counts: proto name or lowerCamelCase.
  std::size_t position = 0;
  int line = 0;
  const google::protobuf::Descriptor* descriptor = descriptor_;
  for (const PathStep& step : SplitFieldPath(field_path)) {
    std::vector<std::string> names = {step.name};
    const google::protobuf::FieldDescriptor* field =
        descriptor != nullptr ? descriptor->FindFieldByName(step.name) : nullptr;
    if (field != nullptr && field->json_name() != step.name) names.push_back(field->json_name());
    std::size_t best = std::string::npos;
    for (const std::string& name : names) {
      const std::regex key("\"" + name + "\"\\s*:");
      std::smatch m;
      const auto begin = text_.cbegin() + static_cast<std::ptrdiff_t>(position);
      if (std::regex_search(begin, text_.cend(), m, key)) {
        best = std::min(best, position + static_cast<std::size_t>(m.position(0)));
      }
    }
    if (best == std::string::npos) break;
    position = best;
    line = LineAndColumn(text_, position).first;
    descriptor = field != nullptr ? field->message_type() : nullptr;
  }
  return line;
}

std::string MessageFile::PointAt(const std::string& server_message, const std::string& root) const {
  const std::string prefix = root + ".";
  const auto colon = server_message.find(':');
  if (server_message.rfind(prefix, 0) == 0 && colon != std::string::npos) {
    const std::string field_path = server_message.substr(prefix.size(), colon - prefix.size());
    const bool one_token = std::none_of(field_path.begin(), field_path.end(),
                                        [](unsigned char c) { return std::isspace(c) != 0; });
    if (one_token) {
      if (const int line = LineOf(field_path); line > 0) {
        return path_ + ":" + std::to_string(line) + ": " + server_message;
      }
    }
  }
  return path_ + ": " + server_message;
}

std::string LoadSceneFile(const std::string& path, v1::Scene* scene) {
  return LoadMessageFile(path, scene, "scene");
}

std::string LoadMessageFile(const std::string& path, google::protobuf::Message* message,
                            const std::string& what) {
  MessageFile file;
  return file.Load(path, message, what);
}

}  // namespace seep::client
