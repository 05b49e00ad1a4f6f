#include "codec/field_path.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace seep::service {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

// Integers beyond 2^53 do not survive a trip through a double exactly.
constexpr double kLargestExactInteger = 9007199254740992.0;

struct PathStep {
  std::string name;
  std::optional<int> index;
};

core::Result<std::vector<PathStep>> ParsePath(std::string_view path) {
  if (path.empty()) return core::InvalidArgument("is required");
  std::vector<PathStep> steps;
  std::size_t at = 0;
  while (at <= path.size()) {
    const std::size_t dot = std::min(path.find('.', at), path.size());
    std::string_view part = path.substr(at, dot - at);
    PathStep step;
    if (const std::size_t open = part.find('['); open != std::string_view::npos) {
      const std::string_view digits = part.substr(open + 1, part.size() - open - 2);
      const bool closed = part.back() == ']';
      const bool numeric = !digits.empty() && digits.size() <= 6 &&
                           digits.find_first_not_of("0123456789") == std::string_view::npos;
      if (!closed || !numeric) {
        return core::InvalidArgument(
            fmt::format("'{}' is not a field name with an index such as effects[0]", part));
      }
      step.index = std::stoi(std::string(digits));
      part = part.substr(0, open);
    }
    if (part.empty())
      return core::InvalidArgument("has an empty step (two dots, or a leading dot)");
    step.name = std::string(part);
    steps.push_back(std::move(step));
    at = dot + 1;
  }
  return steps;
}

std::string FieldNames(const Descriptor& type) {
  std::string names;
  for (int i = 0; i < type.field_count(); ++i) {
    if (i > 0) names += ", ";
    names += type.field(i)->name();
  }
  return names;
}

// A singular field inside a oneof may only be reached (or set) when the base uses that member or
// none.
core::Status CheckOneofMember(const Message& message, const FieldDescriptor& field) {
  const google::protobuf::OneofDescriptor* oneof = field.real_containing_oneof();
  if (oneof == nullptr) return core::Status::Ok();
  const FieldDescriptor* set = message.GetReflection()->GetOneofFieldDescriptor(message, oneof);
  if (set == nullptr || set == &field) {
    if (set == nullptr && field.cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      return core::InvalidArgument(fmt::format(
          "'{}' is a member of oneof '{}', which the base leaves unset: a sweep changes fields "
          "the base has, not which member of a oneof it uses",
          field.name(), oneof->name()));
    }
    return core::Status::Ok();
  }
  return core::InvalidArgument(
      fmt::format("'{}' is a member of oneof '{}', and the base sets '{}': a sweep changes fields "
                  "the base has, not which member of a oneof it uses",
                  field.name(), oneof->name(), set->name()));
}

const char* TypeDescription(const FieldDescriptor& field) {
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE:
    case FieldDescriptor::CPPTYPE_FLOAT:
      return "a floating-point field (give numbers)";
    case FieldDescriptor::CPPTYPE_INT32:
    case FieldDescriptor::CPPTYPE_INT64:
    case FieldDescriptor::CPPTYPE_UINT32:
    case FieldDescriptor::CPPTYPE_UINT64:
      return "an integer field (give integral numbers)";
    case FieldDescriptor::CPPTYPE_BOOL:
      return "a bool field (give flags)";
    case FieldDescriptor::CPPTYPE_ENUM:
      return "an enum field (give texts: value names)";
    case FieldDescriptor::CPPTYPE_STRING:
      return "a string field (give texts)";
    case FieldDescriptor::CPPTYPE_MESSAGE:
      break;
  }
  return "a message field";
}

const char* GivenKind(const v1::SweepSetting& value) {
  switch (value.value_case()) {
    case v1::SweepSetting::kNumber:
      return "a number";
    case v1::SweepSetting::kText:
      return "a text";
    case v1::SweepSetting::kFlag:
      return "a flag";
    case v1::SweepSetting::VALUE_NOT_SET:
      break;
  }
  return "no value";
}

// The number as an integer of the field's type, or why it cannot be one.
core::Result<std::int64_t> SignedValue(double x, std::int64_t lowest, std::int64_t highest) {
  if (!std::isfinite(x) || std::floor(x) != x) {
    return core::InvalidArgument(fmt::format("is not an integer (got {})", x));
  }
  if (std::fabs(x) > kLargestExactInteger) {
    return core::InvalidArgument(fmt::format("is beyond 2^53, where numbers lose digits ({})", x));
  }
  if (x < static_cast<double>(lowest) || x > static_cast<double>(highest)) {
    return core::InvalidArgument(
        fmt::format("is outside the field's range {}..{} (got {})", lowest, highest, x));
  }
  return static_cast<std::int64_t>(x);
}

core::Status SetInteger(const FieldSlot& slot, double x) {
  Message& m = *slot.message;
  const Reflection& r = *m.GetReflection();
  const FieldDescriptor* f = slot.field;
  const bool repeated = slot.index >= 0;
  switch (f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32: {
      SEEP_ASSIGN_OR_RETURN(const std::int64_t v, SignedValue(x, INT32_MIN, INT32_MAX));
      const auto v32 = static_cast<std::int32_t>(v);
      repeated ? r.SetRepeatedInt32(&m, f, slot.index, v32) : r.SetInt32(&m, f, v32);
      break;
    }
    case FieldDescriptor::CPPTYPE_INT64: {
      SEEP_ASSIGN_OR_RETURN(const std::int64_t v, SignedValue(x, INT64_MIN, INT64_MAX));
      repeated ? r.SetRepeatedInt64(&m, f, slot.index, v) : r.SetInt64(&m, f, v);
      break;
    }
    case FieldDescriptor::CPPTYPE_UINT32: {
      SEEP_ASSIGN_OR_RETURN(const std::int64_t v, SignedValue(x, 0, UINT32_MAX));
      const auto u32 = static_cast<std::uint32_t>(v);
      repeated ? r.SetRepeatedUInt32(&m, f, slot.index, u32) : r.SetUInt32(&m, f, u32);
      break;
    }
    default: {  // CPPTYPE_UINT64
      SEEP_ASSIGN_OR_RETURN(const std::int64_t v, SignedValue(x, 0, INT64_MAX));
      const auto u64 = static_cast<std::uint64_t>(v);
      repeated ? r.SetRepeatedUInt64(&m, f, slot.index, u64) : r.SetUInt64(&m, f, u64);
      break;
    }
  }
  return core::Status::Ok();
}

}  // namespace

core::Result<FieldSlot> ResolveFieldPath(Message& root, std::string_view path) {
  SEEP_ASSIGN_OR_RETURN(const std::vector<PathStep> steps, ParsePath(path));
  Message* current = &root;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const PathStep& step = steps[i];
    const Descriptor& type = *current->GetDescriptor();
    const FieldDescriptor* field = type.FindFieldByName(step.name);
    if (field == nullptr) {
      return core::InvalidArgument(fmt::format("{} has no field '{}' (its fields: {})",
                                               type.full_name(), step.name, FieldNames(type)));
    }
    const Reflection& reflection = *current->GetReflection();
    int index = -1;
    if (field->is_map()) {
      return core::InvalidArgument(
          fmt::format("'{}' is a map: a sweep cannot address it", step.name));
    }
    if (field->is_repeated()) {
      if (!step.index) {
        return core::InvalidArgument(fmt::format(
            "'{}' is a repeated field: name one element, e.g. {}[0]", step.name, step.name));
      }
      const int size = reflection.FieldSize(*current, field);
      if (*step.index >= size) {
        return core::InvalidArgument(
            fmt::format("{}[{}]: the base has {} element(s) there", step.name, *step.index, size));
      }
      index = *step.index;
    } else if (step.index) {
      return core::InvalidArgument(
          fmt::format("'{}' is not a repeated field: it takes no index", step.name));
    } else {
      SEEP_RETURN_IF_ERROR(CheckOneofMember(*current, *field));
    }
    const bool last = i + 1 == steps.size();
    const bool is_message = field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE;
    if (last && is_message) {
      return core::InvalidArgument(fmt::format(
          "'{}' is a message ({}): a sweep sets a number, text or flag; name one of its fields "
          "({})",
          step.name, field->message_type()->full_name(), FieldNames(*field->message_type())));
    }
    if (last) return FieldSlot{current, field, index};
    if (!is_message) {
      return core::InvalidArgument(
          fmt::format("'{}' is {}, not a message: the path cannot go on past it", step.name,
                      TypeDescription(*field)));
    }
    current = index >= 0 ? reflection.MutableRepeatedMessage(current, field, index)
                         : reflection.MutableMessage(current, field);
  }
  return core::Internal("field path: no steps");  // ParsePath returns at least one
}

core::Status SetFieldValue(const FieldSlot& slot, const v1::SweepSetting& value) {
  Message& m = *slot.message;
  const Reflection& r = *m.GetReflection();
  const FieldDescriptor* f = slot.field;
  const bool repeated = slot.index >= 0;
  const auto wrong_kind = [&]() {
    return core::InvalidArgument(
        fmt::format("the field is {}; got {}", TypeDescription(*f), GivenKind(value)));
  };
  switch (f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_DOUBLE:
      if (!value.has_number()) return wrong_kind();
      repeated ? r.SetRepeatedDouble(&m, f, slot.index, value.number())
               : r.SetDouble(&m, f, value.number());
      return core::Status::Ok();
    case FieldDescriptor::CPPTYPE_FLOAT: {
      if (!value.has_number()) return wrong_kind();
      const auto x = static_cast<float>(value.number());
      repeated ? r.SetRepeatedFloat(&m, f, slot.index, x) : r.SetFloat(&m, f, x);
      return core::Status::Ok();
    }
    case FieldDescriptor::CPPTYPE_INT32:
    case FieldDescriptor::CPPTYPE_INT64:
    case FieldDescriptor::CPPTYPE_UINT32:
    case FieldDescriptor::CPPTYPE_UINT64:
      if (!value.has_number()) return wrong_kind();
      return SetInteger(slot, value.number());
    case FieldDescriptor::CPPTYPE_BOOL:
      if (!value.has_flag()) return wrong_kind();
      repeated ? r.SetRepeatedBool(&m, f, slot.index, value.flag())
               : r.SetBool(&m, f, value.flag());
      return core::Status::Ok();
    case FieldDescriptor::CPPTYPE_ENUM: {
      if (!value.has_text()) return wrong_kind();
      const google::protobuf::EnumValueDescriptor* e =
          f->enum_type()->FindValueByName(value.text());
      if (e == nullptr) {
        std::string names;
        for (int i = 0; i < f->enum_type()->value_count(); ++i) {
          if (i > 0) names += ", ";
          names += f->enum_type()->value(i)->name();
        }
        return core::InvalidArgument(fmt::format("'{}' is not a value of {} (its values: {})",
                                                 value.text(), f->enum_type()->full_name(), names));
      }
      repeated ? r.SetRepeatedEnum(&m, f, slot.index, e) : r.SetEnum(&m, f, e);
      return core::Status::Ok();
    }
    case FieldDescriptor::CPPTYPE_STRING:
      if (!value.has_text()) return wrong_kind();
      repeated ? r.SetRepeatedString(&m, f, slot.index, value.text())
               : r.SetString(&m, f, value.text());
      return core::Status::Ok();
    case FieldDescriptor::CPPTYPE_MESSAGE:
      break;
  }
  return wrong_kind();  // ResolveFieldPath never ends on a message
}

core::Result<std::uint64_t> ReadUnsignedValue(const FieldSlot& slot) {
  const Message& m = *slot.message;
  const Reflection& r = *m.GetReflection();
  const FieldDescriptor* f = slot.field;
  const bool repeated = slot.index >= 0;
  switch (f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_UINT64:
      return repeated ? r.GetRepeatedUInt64(m, f, slot.index) : r.GetUInt64(m, f);
    case FieldDescriptor::CPPTYPE_UINT32:
      return repeated ? r.GetRepeatedUInt32(m, f, slot.index) : r.GetUInt32(m, f);
    case FieldDescriptor::CPPTYPE_INT64: {
      const std::int64_t v = repeated ? r.GetRepeatedInt64(m, f, slot.index) : r.GetInt64(m, f);
      return static_cast<std::uint64_t>(std::max<std::int64_t>(v, 0));
    }
    case FieldDescriptor::CPPTYPE_INT32: {
      const std::int32_t v = repeated ? r.GetRepeatedInt32(m, f, slot.index) : r.GetInt32(m, f);
      return static_cast<std::uint64_t>(std::max<std::int32_t>(v, 0));
    }
    default:
      break;
  }
  return core::InvalidArgument(
      fmt::format("a seed is an integer field; this one is {}", TypeDescription(*f)));
}

std::string SettingValueText(const v1::SweepSetting& value) {
  switch (value.value_case()) {
    case v1::SweepSetting::kNumber:
      return fmt::format("{}", value.number());
    case v1::SweepSetting::kText:
      return value.text();
    case v1::SweepSetting::kFlag:
      return value.flag() ? "true" : "false";
    case v1::SweepSetting::VALUE_NOT_SET:
      break;
  }
  return "(none)";
}

}  // namespace seep::service
