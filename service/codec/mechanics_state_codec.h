// core::MechanicsSnapshot <-> seep.v1.MechanicsState (the moving part of a checkpoint). Field for
// field; the shapes are checked by core when the snapshot is restored.
#pragma once

#include "seep/core/run/simulation_snapshot.h"
#include "seep/v1/checkpoint.pb.h"

namespace seep::service {

void MechanicsStateToProto(const core::MechanicsSnapshot& snapshot, v1::MechanicsState* out);
core::MechanicsSnapshot MechanicsStateFromProto(const v1::MechanicsState& state);

}  // namespace seep::service
