// core::SimulationSnapshot <-> seep.v1.SimulationState, the state inside a checkpoint file.
#pragma once

#include <string>

#include "seep/core/run/simulation_snapshot.h"
#include "seep/core/status.h"
#include "seep/v1/checkpoint.pb.h"

namespace seep::service {

void SimulationStateToProto(const core::SimulationSnapshot& snapshot, v1::SimulationState* out);
// Wire checks only (series row length; a staged run's times and peaks finite, DATA_LOSS naming
// the field); whether the state fits the scene is core::Simulation::Restore's check.
core::Result<core::SimulationSnapshot> SimulationStateFromProto(const v1::SimulationState& state);

// Deterministic bytes of a snapshot (same snapshot and build -> same bytes), for checkpoint
// files and for the result hash that proves a resumed run ended where an uninterrupted one does.
std::string SerializeSimulationState(const core::SimulationSnapshot& snapshot);
core::Result<core::SimulationSnapshot> ParseSimulationState(const std::string& bytes);

}  // namespace seep::service
