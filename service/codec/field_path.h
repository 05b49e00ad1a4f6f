// Field paths into a seep.v1 message ("boundary.inlet_pressure_pa",
// "effects[2].injection.rate_m2_s", "target_permeabilities_m2[0]"), resolved and set with
// protobuf reflection: what a sweep uses to make its jobs from one base scene or calibration.
#pragma once

#include <google/protobuf/message.h>

#include <string>
#include <string_view>

#include "seep/core/status.h"
#include "seep/v1/job_service.pb.h"

namespace seep::service {

// Where a path leads: the message holding the field, the field, and the element of a repeated
// field (-1 for a singular one).
struct FieldSlot {
  google::protobuf::Message* message = nullptr;
  const google::protobuf::FieldDescriptor* field = nullptr;
  int index = -1;
};

// Resolves `path` in `root` down to a scalar field (a number, string, enum or bool). Every step
// must be a field of its message; an index must name an element `root` already has; a message
// inside a oneof must be the member `root` sets (a sweep changes fields of the base, not which
// member it uses). INVALID_ARGUMENT says what is wrong (without the path, which the caller
// names). Unset singular messages on the way are created in `root`.
core::Result<FieldSlot> ResolveFieldPath(google::protobuf::Message& root, std::string_view path);

// Sets the slot to the setting's value: a number for a floating-point or integer field (an
// integral one within the integer type's range), a text for a string or enum field (the enum
// value's name), a flag for a bool. INVALID_ARGUMENT names the field's type and the value.
core::Status SetFieldValue(const FieldSlot& slot, const v1::SweepSetting& value);

// An integer field's value (for a replicate seed's start); INVALID_ARGUMENT for another type.
core::Result<std::uint64_t> ReadUnsignedValue(const FieldSlot& slot);

// The value as text for messages: a number as the shortest text that reads back the same.
std::string SettingValueText(const v1::SweepSetting& value);

}  // namespace seep::service
