// core::SceneFields -> seep.v1.JobFields, the packed arrays GetJobFields returns.
#pragma once

#include "seep/core/run/scene_fields.h"
#include "seep/v1/job_service.pb.h"

namespace seep::service {

void SceneFieldsToProto(const core::SceneFields& fields, v1::JobFields* out);

}  // namespace seep::service
