// A permeameter between two drained platens: the permeability a walled sample shows along one
// axis while it is loaded (a biaxial or oedometer test with seepage), from the flow between two
// drained side walls that face each other (left and right, or bottom and top) at different
// pressures, k = mu Q L / (W dP): Q the mean of the rates out of the high platen and into the low
// one in the steady flow of the network as it is now (a probe solve on a copy: the permeability
// of the current geometry and apertures, without the fluid a deforming skeleton pumps), L the
// distance between them now, W the sample's extent across (between the other two walls when
// both exist, else the particles' extent), dP their pressure difference now.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "seep/core/effects/live_state.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core::effects_internal {

struct PlatenPair {
  std::size_t high = 0, low = 0;  // wall indices in the walls effect
  bool along_x = true;            // left/right (else bottom/top)
};

// The scene's one pair of opposite drained side walls at different pressures, if it has exactly
// one such pair (pressures as the scene states them at set-up).
std::optional<PlatenPair> FindPlatenPair(const SceneSpec& scene);

// k between the pair now (NaN while the pressures are equal).
double PlatenPermeability(const LiveState& s, const PlatenPair& pair);

}  // namespace seep::core::effects_internal
