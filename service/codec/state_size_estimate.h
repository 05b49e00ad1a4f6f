// How big a scene's checkpointed state can get, estimated from the scene alone at submit: a
// state that protobuf cannot serialize (one message is limited to 2 GiB) could never be
// checkpointed, so such a scene is refused before anything is stored or run.
#pragma once

#include <cstdint>

#include "seep/core/spec/scene_spec.h"
#include "seep/core/status.h"

namespace seep::service {

// Largest message protobuf serializes (INT_MAX bytes).
inline constexpr std::uint64_t kMaxSerializedStateBytes = 2147483647;

struct StateSizeEstimate {
  std::uint64_t particles = 0;
  std::uint64_t bytes_per_particle = 0;  // an upper bound for this kind of scene
  std::uint64_t series_bytes = 0;        // the time series at its row cap
  std::uint64_t total_bytes = 0;
};

StateSizeEstimate EstimateStateSize(const core::SceneSpec& scene);

// INVALID_ARGUMENT "scene.packing: ..." with the estimate's figures and the largest particle
// count that fits, when the estimate exceeds kMaxSerializedStateBytes.
core::Status CheckStateFitsACheckpoint(const core::SceneSpec& scene);

// A running job's peak resident memory, estimated from the scene alone at submit (the admission
// check against the memory a job may use).
struct PeakMemoryEstimate {
  std::uint64_t particles = 0;
  std::uint64_t bytes_per_particle = 0;  // an upper bound for this kind of scene
  std::uint64_t total_bytes = 0;         // with the process's own
};

PeakMemoryEstimate EstimatePeakMemory(const core::SceneSpec& scene);

// RESOURCE_EXHAUSTED "scene.packing: ..." with the estimate's figures and the largest particle
// count that fits, when the estimate exceeds limit_bytes (0: no limit).
core::Status CheckJobFitsMemory(const core::SceneSpec& scene, std::uint64_t limit_bytes);

}  // namespace seep::service
