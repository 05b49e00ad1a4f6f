// seep.v1.Stage -> core::StageSpec (wire checks only: every Setting and EndCondition given sets one
// arm of its oneof, breakthrough is true; proto3 defaults mapped to "unset"). Physical ranges,
// schedules and end conditions that need an effect are core::ValidateScene's. Errors name the
// field by its path, e.g. "scene.stages[0].end[1]: set one end condition (duration_s, ...)".
#pragma once

#include <cstddef>
#include <vector>

#include "seep/core/spec/stage_spec.h"
#include "seep/core/status.h"
#include "seep/v1/scene.pb.h"

namespace seep::service {

// Appends the stage to *out (a status return, not Result: see AppendEffectFromProto on GCC 12
// and variants moved out of a Result).
core::Status AppendStageFromProto(const v1::Stage& stage, std::size_t index,
                                  std::vector<core::StageSpec>* out);

}  // namespace seep::service
