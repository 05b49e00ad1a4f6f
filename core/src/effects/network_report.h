// What the flow effect reports of a scene's network: the boundary rates, the Darcy or radial
// figures, the pressure range, the counts and the porosity (report metrics and series columns).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "seep/core/effects/effect.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core::effects_internal {

// The network's series columns (after "time_s"): the two boundary rates of the scene's boundary
// kind, the pressure range and the mass-balance error of the step that ended at the sample.
void AddNetworkSeriesColumns(const SceneSpec& scene, std::vector<std::string>* columns);
void AddNetworkSample(const SceneSpec& scene, const SceneNetwork& net, double step_error,
                      std::vector<double>* row);

// Boundary rates, permeability (linear) or well figures (radial), each boundary region's flow
// and domain count, pressure range, counts and porosity_2d from `pore_volume` (the V_p a report
// shows, per flow node). node_weight: W_n per flow node when the fluid has weight
// (network/fluid_weight.h), else empty; the permeability is then measured against the head drop
// between the reservoirs, not the pressure drop.
void AddNetworkMetrics(const SceneSpec& scene, const SceneNetwork& net,
                       std::span<const double> pore_volume, std::span<const double> node_weight,
                       Metrics* m);

}  // namespace seep::core::effects_internal
