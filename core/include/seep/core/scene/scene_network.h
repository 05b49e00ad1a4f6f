// SceneNetwork: the pipe network of a scene, built from its packing.
//
// packing -> contacts (gap <= contact_gap_m, plus a round-off tolerance) -> domains and pipes
// (faces of the contact graph) -> FlowNetwork. Node ids of the FlowNetwork are the domain ids of
// the detection, followed by two reservoir nodes with fixed pressure: the inlet at the low end of
// the flow axis and the outlet at the high end (physics.md §2.4, option A). A contact on the
// sample's outer loop whose two particles both lie in the edge layer at one end (their extreme
// coordinate within one mean radius of the sample's end) becomes a pipe from the domain beside it
// to that end's reservoir. The other hull contacts are no-flow.
//
// Darcy geometry of the sample, for the permeability k = mu Q L / (H dP):
//   length_m   extent of the particles along the axis (surface to surface): the reservoirs sit
//              at the particles' outer surfaces, one pipe beyond the edge domains;
//   width_m    area of the domains divided by the extent of their loop particles' centres along
//              the axis: the mean transverse size of the region the fluid flows through.
// On a square lattice these make k exactly a^3/(24R) (physics.md §1.3).
#pragma once

#include <cstdint>
#include <vector>

#include "seep/core/flow/aperture_law.h"
#include "seep/core/flow/flow_network.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/scene/scene_spec.h"

namespace seep::core {

struct SceneNetwork {
  Packing packing;
  ContactList contacts;
  DomainNetwork domains;
  FlowNetwork flow;
  std::int32_t inlet_node = -1;
  std::int32_t outlet_node = -1;
  std::int64_t inlet_pipes = 0;
  std::int64_t outlet_pipes = 0;
  double length_m = 0.0;
  double width_m = 0.0;
  double mean_radius_m = 0.0;
};

// Builds the packing a scene describes (lattice, random or an explicit list).
Result<Packing> BuildScenePacking(const PackingSpec& spec);

// Builds the network with apertures from the scene's aperture law at zero contact force (a rigid,
// unloaded packing: a = a0 + m g). Free domains start at boundary.initial_pressure_pa.
Result<SceneNetwork> BuildSceneNetwork(const SceneSpec& scene);

}  // namespace seep::core
