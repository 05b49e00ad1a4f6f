// Fluid weight on a scene's network: the head term of the pipes, the hydrostatic start and the
// reference points they are measured at (docs/guide/fluid-weight.md).
//
// The model. With a density rho_f and a gravity effect g, w = rho_f g (Pa/m) and the fluid of
// every face is at rest within the face: p(x) = P_n + w.(x - x_n), P_n the node's pressure at its
// reference point x_n. Pipe flow follows the head P - w.x, so the pipe law becomes
//   q_ab = C (P_b - P_a - (W_b - W_a)),   W_n = w.x_n ("weight pressure" of node n, Pa),
// i.e. the per-pipe head offset W_b - W_a of flow_network.h. Reference points:
//   - a domain (free, source or fixed, e.g. the radial well): the centroid of the polygon through
//     its loop's particle centres, from the current positions (they move with the particles);
//   - a reservoir node (ids past the domains: a permeameter's inlet and outlet, the radial outer
//     ring): the mean contact point of its pipes, i.e. the middle of the face it wets. A
//     reservoir is fluid at rest, so its head is the same along the whole face: the pressure a
//     scene gives it (inlet_pressure_pa, outer_pressure_pa) is the pressure at that point, and it
//     is w per metre higher lower down the face. A permeameter at p_in = p_out along a vertical
//     face is therefore at rest, as a real one is.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "seep/core/coupling/particle_view.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {

// rho_f g, Pa/m (the pressure gradient of fluid at rest).
struct FluidWeight {
  double x = 0.0;
  double y = 0.0;
};

// The scene's fluid weight, or none when the fluid has no density or the scene no gravity.
std::optional<FluidWeight> SceneFluidWeight(const SceneSpec& scene);

// W_n = w.(x_n - o) for every node of net.flow (see above), o the network's weight origin
// (SceneNetwork::weight_origin_x_m, a point of the sample), the particles at `positions` (the ids
// of net.packing). A reservoir without pipes gets 0 (nothing flows through it). Allocates only when
// *out grows.
Status ComputeNodeWeightPressures(const SceneNetwork& net, const ParticleView& positions,
                                  const FluidWeight& weight, std::vector<double>* out);

// A stretch of wall a domain's loop runs along: its two wall vertices (loop ids, in the loop's
// order) and its wall. The fluid weight's part of a wall's load is integrated over these.
struct WallStretch {
  std::int32_t from = 0, to = 0, wall = 0;
};
std::vector<WallStretch> WettedWallStretches(const DomainNetwork& domains);

// Sets the head offset W_b - W_a of every pipe of *flow (bumps its coefficient version).
Status ApplyHeadOffsets(std::span<const double> node_weight, FlowNetwork* flow);

// The hydrostatic start (BoundarySpec::initial_pressure_hydrostatic): every non-fixed node of
// net->flow at P_n = initial_pressure_pa + W_n - w.(x_ref - o).
void ApplyHydrostaticStart(const SceneSpec& scene, const FluidWeight& weight,
                           std::span<const double> node_weight, SceneNetwork* net);

}  // namespace seep::core
