// Reads a scene file (or any seep.v1 message, e.g. a Calibration): protobuf text format
// (.textproto, .txtpb, .pbtxt) or JSON (.json). Errors name the file, the line and column, and
// what the parser expected.
#pragma once

#include <google/protobuf/message.h>

#include <string>

#include "seep/v1/scene.pb.h"

namespace seep::client {

// Returns an empty string on success, else the error message.
std::string LoadSceneFile(const std::string& path, v1::Scene* scene);
// The same for any message; `what` names the file's kind in errors ("scene", "calibration").
std::string LoadMessageFile(const std::string& path, google::protobuf::Message* message,
                            const std::string& what);

}  // namespace seep::client
