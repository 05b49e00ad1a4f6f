// Reads a scene file: protobuf text format (.textproto, .txtpb, .pbtxt) or JSON (.json).
// Errors name the file, the line and column, and what the parser expected.
#pragma once

#include <string>

#include "seep/v1/scene.pb.h"

namespace seep::client {

// Returns an empty string on success, else the error message.
std::string LoadSceneFile(const std::string& path, v1::Scene* scene);

}  // namespace seep::client
