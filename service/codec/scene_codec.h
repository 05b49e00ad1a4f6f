// seep.v1.Scene -> core::SceneSpec. The only place where the scene's wire form and its core form
// meet. Wire checks (enums left UNSPECIFIED, a missing oneof) happen here; physical ranges are
// checked by core::ValidateScene. Every error names the field by its path in the scene.
#pragma once

#include "seep/core/spec/scene_spec.h"
#include "seep/core/status.h"
#include "seep/v1/scene.pb.h"

namespace seep::service {

// The wire checks only. For a scene that core::Simulation::Create validates next (it calls
// core::ValidateScene first): a stored scene at the start of its run, or for GetJobFields.
core::Result<core::SceneSpec> DecodeScene(const v1::Scene& scene);
// DecodeScene, then core::ValidateScene and the estimate of the state's size
// (CheckStateFitsACheckpoint): what a submit checks before anything is stored.
core::Result<core::SceneSpec> SceneFromProto(const v1::Scene& scene);

}  // namespace seep::service
