// SceneFields: the state of a Simulation as plain arrays, for plotting and export (the job
// service's GetJobFields, the `seep export` and `seep plot` commands).
//
// Everything comes from Simulation::network(): particles from the packing, domains (centroid,
// pressure, V_d, V_p and their loops) from the detection and the flow network, one entry per
// flow-network pipe with its flow rate q = C (P_b - P_a) (from b into a). Reservoir nodes are not
// domains here: a pipe to one has domain_b = -1 and ends at its contact point.
//
// Where the scene has a closed-form pressure it is evaluated per domain:
//   linear boundary, steady solver:     P = P_in + (P_out - P_in) xi (exact on lattices);
//   linear boundary, transient solver:  the series of docs/physics.md §3.2 (a) from the uniform
//                                       initial pressure P_0, superposed for the two ends:
//                                       P = P_0 + (P_in - P_0) S(xi, T) + (P_out - P_0) S(1 - xi,
//                                       T) with T = c t / L^2, c = k K_f / (mu n_s);
//   radial boundary, steady solver:     Thiem between the well and the outer reservoir radius.
// xi = (s - s_in) / L, s the coordinate along the flow axis, s_in the inlet reservoir's effective
// position and L the network's length_m (scene_network.h), so the reservoirs sit at xi = 0 and 1.
// k is the affine estimate over every pipe, reservoir pipes included (a reservoir pipe spans the
// centroid and its image through the contact point), over the Darcy box length_m * width_m: exact
// on lattices. n_s = sum(V_s) / sum(V_d) for the scene's storage volume (1 for V_d).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "seep/core/run/simulation.h"

namespace seep::core {

struct SceneFields {
  std::uint64_t step = 0;
  double time_s = 0.0;

  std::vector<double> particle_x;
  std::vector<double> particle_y;
  std::vector<double> particle_radius;

  std::vector<double> domain_centroid_x;
  std::vector<double> domain_centroid_y;
  std::vector<double> domain_pressure;
  std::vector<double> domain_apparent_volume;     // V_d
  std::vector<double> domain_pore_volume;         // V_p
  std::vector<std::int32_t> domain_loop_offsets;  // CSR, size domains + 1
  std::vector<std::int32_t> domain_loop_particles;
  // Loop ids from the particle count on: wall vertices, at these positions (domain_walls.h).
  std::vector<double> wall_vertex_x, wall_vertex_y;

  std::vector<std::int32_t> pipe_domain_a;
  std::vector<std::int32_t> pipe_domain_b;  // -1: a reservoir
  std::vector<std::int32_t> pipe_particle_i;
  std::vector<std::int32_t> pipe_particle_j;
  std::vector<double> pipe_x0;  // domain a's centroid
  std::vector<double> pipe_y0;
  std::vector<double> pipe_x1;  // domain b's centroid, or the contact point
  std::vector<double> pipe_y1;
  std::vector<double> pipe_aperture;
  std::vector<double> pipe_conductance;
  std::vector<double> pipe_flow;  // q = C (P_b - P_a - head offset), m^2/s, from b into a

  // Empty analytic_kind: the scene has no closed-form pressure (the vectors below are empty).
  std::string analytic_kind;  // "linear_steady", "linear_transient", "radial_steady"
  std::vector<double> domain_analytic_pressure;
  std::vector<double> domain_axis_coordinate;  // s - s_in (linear) or the radius (radial), m
  double axis_length = 0.0;                    // L (linear) or the outer reservoir radius
  std::string axis_name;                       // "x", "y" or "r"
};

SceneFields CollectSceneFields(const Simulation& sim);

}  // namespace seep::core
