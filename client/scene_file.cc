#include "scene_file.h"

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/json_util.h>

#include <filesystem>
#include <fstream>
#include <sstream>

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

}  // namespace

std::string LoadSceneFile(const std::string& path, v1::Scene* scene) {
  return LoadMessageFile(path, scene, "scene");
}

std::string LoadMessageFile(const std::string& path, google::protobuf::Message* scene,
                            const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return path + ": cannot open the " + what + " file";
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();

  if (EndsWith(path, ".json")) {
    google::protobuf::util::JsonParseOptions options;
    options.ignore_unknown_fields = false;
    const auto status = google::protobuf::util::JsonStringToMessage(text, scene, options);
    if (!status.ok()) return path + ": " + std::string(status.message());
    return {};
  }
  google::protobuf::TextFormat::Parser parser;
  CollectFirstError errors;
  parser.RecordErrorsTo(&errors);
  if (!parser.ParseFromString(text, scene)) {
    return path + ":" + (errors.first().empty() ? std::string("parse error") : errors.first());
  }
  return {};
}

}  // namespace seep::client
