// Reads a scene file (or any seep.v1 message, e.g. a Calibration): protobuf text format
// (.textproto, .txtpb, .pbtxt) or JSON (.json). Errors point at the file, line and field: a parse
// error as "FILE:LINE:COL: what the parser expected", and a field the server rejects (its message
// starts with the field path, "scene.fluid.viscosity_pa_s: must be > 0") as
// "FILE:LINE: scene.fluid.viscosity_pa_s: ..." with the line where that field is set.
#pragma once

#include <google/protobuf/message.h>
#include <google/protobuf/text_format.h>

#include <memory>
#include <string>

#include "seep/v1/scene.pb.h"

namespace seep::client {

// One message file, read and parsed, that remembers where each field was written.
class MessageFile {
 public:
  // Reads and parses `path` into `message`; `what` names the file's kind in errors ("scene",
  // "calibration"). Returns an empty string on success, else the error message (see above).
  std::string Load(const std::string& path, google::protobuf::Message* message,
                   const std::string& what);

  // The 1-based line where the field at `field_path` is written ("fluid.viscosity_pa_s",
  // "target_permeabilities_m2[3]", relative to the file's message), or of its nearest written
  // ancestor when the field itself is absent (a missing value is reported on its block); 0 when
  // nothing of the path is in the file.
  int LineOf(const std::string& field_path) const;

  // A server error that starts with "<root>.<field path>:" becomes "FILE:LINE: <message>";
  // anything else becomes "FILE: <message>". root is "scene" or "calibration".
  std::string PointAt(const std::string& server_message, const std::string& root) const;

  const std::string& path() const { return path_; }

 private:
  int LineOfInText(const std::string& field_path) const;
  int LineOfInJson(const std::string& field_path) const;

  std::string path_;
  std::string text_;
  bool json_ = false;
  const google::protobuf::Descriptor* descriptor_ = nullptr;
  std::unique_ptr<google::protobuf::TextFormat::ParseInfoTree> locations_;
};

// Returns an empty string on success, else the error message.
std::string LoadSceneFile(const std::string& path, v1::Scene* scene);
// The same for any message; `what` names the file's kind in errors ("scene", "calibration").
std::string LoadMessageFile(const std::string& path, google::protobuf::Message* message,
                            const std::string& what);

}  // namespace seep::client
