#include "refusal_rule.h"

#include <fmt/format.h>

#include <cctype>

namespace seep::fuzz {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;

// Skips one [..] index (a number or a quoted key with escapes); false when it does not close.
bool SkipIndex(const std::string& text, std::size_t& at) {
  bool quoted = false;
  for (++at; at < text.size(); ++at) {
    const char c = text[at];
    if (quoted && c == '\\') {
      ++at;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ']' && !quoted) {
      ++at;
      return true;
    }
  }
  return false;
}

}  // namespace

std::string FieldPathProblem(const Descriptor& request, const std::string& message) {
  const Descriptor* at = &request;
  std::size_t pos = 0;
  int resolved = 0;
  for (;;) {
    std::size_t end = pos;
    while (end < message.size() &&
           (std::isalnum(static_cast<unsigned char>(message[end])) || message[end] == '_')) {
      ++end;
    }
    const std::string name = message.substr(pos, end - pos);
    if (name.empty()) return fmt::format("no field name at character {}", pos);
    if (at == nullptr) {
      return fmt::format("'{}' follows a field that holds no message", name);
    }
    const FieldDescriptor* field = at->FindFieldByName(name);
    if (field == nullptr) {
      if (at->FindOneofByName(name) == nullptr) {
        return fmt::format("'{}' is no field of {}", name, at->full_name());
      }
      at = nullptr;  // a oneof's name ends the path
    } else if (field->is_map()) {
      at = field->message_type()->map_value()->message_type();
    } else {
      at = field->message_type();
    }
    ++resolved;
    pos = end;
    while (pos < message.size() && message[pos] == '[') {
      if (!SkipIndex(message, pos)) return "an index that does not close";
    }
    if (pos < message.size() && message[pos] == '.') {
      ++pos;
      continue;
    }
    break;
  }
  // The path ends the message, or is followed by ':' or ' ' (" ('name'): ...").
  if (pos == message.size() || message[pos] == ':' || message[pos] == ' ') return "";
  return fmt::format("the path is followed by '{}'", message[pos]);
}

std::string RefusalProblem(const Descriptor& request, const std::string& method,
                           const std::string& id, const grpc::Status& status) {
  const std::string& message = status.error_message();
  switch (status.error_code()) {
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::OUT_OF_RANGE:
    case grpc::StatusCode::ALREADY_EXISTS: {
      if (message.rfind(method + ": the request's bytes do not decode", 0) == 0) return "";
      const std::string problem = FieldPathProblem(request, message);
      return problem.empty() ? "" : "names no field of the request: " + problem;
    }
    case grpc::StatusCode::NOT_FOUND:
    case grpc::StatusCode::FAILED_PRECONDITION: {
      if (FieldPathProblem(request, message).empty()) return "";
      if (!id.empty() && message.find(id) != std::string::npos) return "";
      return "names neither a field of the request nor the id it sent";
    }
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return message.empty() ? "RESOURCE_EXHAUSTED without a word on the limit" : "";
    default:
      return "not a refusal but a failure of the service";
  }
}

}  // namespace seep::fuzz
