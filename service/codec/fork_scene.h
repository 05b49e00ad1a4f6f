// CheckForkScene: whether a fork's scene continues its parent's (SubmitJobRequest.from_job_id).
//
// A fork starts from the parent's checkpoint, so everything that state was made by must be the
// same: the packing, fluid, apertures, boundary, solver and effects, and every stage that had
// begun at the checkpoint. Only the name, solver.progress_every (how often progress is sampled)
// and the stages after the checkpoint's current one may differ; those may be changed, removed or
// added to. Messages are compared as messages (field presence included), not as decoded specs.
#pragma once

#include <cstdint>
#include <string>

#include "seep/core/status.h"
#include "seep/v1/scene.pb.h"

namespace seep::service {

// Where in the parent's run the fork starts.
struct ForkPoint {
  std::string parent_job_id;
  std::uint64_t step = 0;  // of the parent's checkpoint
  // The checkpoint's stage (StageRunState::index): 0-based, the parent's stage count once every
  // stage has ended (its final state).
  std::uint32_t stage_index = 0;
};

// OK when `fork` may continue `parent` from `at`; else INVALID_ARGUMENT naming the first field
// that differs ("scene.packing: ...", "scene.stages[1]: ...") and why.
core::Status CheckForkScene(const v1::Scene& parent, const v1::Scene& fork, const ForkPoint& at);

}  // namespace seep::service
