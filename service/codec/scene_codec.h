// seep.v1.Scene -> core::SceneSpec. The only place where the scene's wire form and its core form
// meet. Wire checks (enums left UNSPECIFIED, a missing oneof) happen here; physical ranges are
// checked by core::ValidateScene. Every error names the field by its path in the scene.
#pragma once

#include "seep/core/spec/scene_spec.h"
#include "seep/core/status.h"
#include "seep/v1/scene.pb.h"

namespace seep::service {

core::Result<core::SceneSpec> SceneFromProto(const v1::Scene& scene);

}  // namespace seep::service
