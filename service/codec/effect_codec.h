// seep.v1.Effect -> core::EffectSpec (wire checks only: oneof set, enums not UNSPECIFIED, proto3
// zero defaults mapped; physical ranges are core::ValidateEffects'). Errors name the list entry,
// e.g. "scene.effects[2].walls.walls[0].side: must be WALL_SIDE_LEFT, ... (got
// WALL_SIDE_UNSPECIFIED)".
#pragma once

#include <cstddef>
#include <vector>

#include "seep/core/spec/effect_spec.h"
#include "seep/core/status.h"
#include "seep/v1/scene.pb.h"

namespace seep::service {

// Appends the effect to *out (a status return, not Result<variant>: GCC 12 at -O3 reports a
// false maybe-uninitialized on moving the variant out of a Result).
core::Status AppendEffectFromProto(const v1::Effect& effect, std::size_t index,
                                   std::vector<core::EffectSpec>* out);

}  // namespace seep::service
