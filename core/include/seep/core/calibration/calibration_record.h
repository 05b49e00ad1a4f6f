// CalibrationRecord: the outcome of calibrating the residual aperture to one target permeability,
// with everything needed to reproduce or judge it (the packing, fluid, aperture law, stress state
// and flow direction it holds for, and how good the affine first guess of docs/physics.md §1.3 (C1)
// was).
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "seep/core/spec/scene_spec.h"

namespace seep::core {

struct CalibrationPackingStats {
  std::size_t particle_count = 0;
  std::size_t contact_count = 0;  // pairs with gap <= packing.contact_gap_m
  std::size_t domain_count = 0;
  std::size_t pipe_count = 0;  // flow pipes, the reservoir pipes included
  double porosity_2d = 0.0;    // sum V_p / sum V_d over the domains
  double mean_radius_m = 0.0;
  double radius_std_dev_m = 0.0;  // population standard deviation of the radii
  double min_radius_m = 0.0;
  double max_radius_m = 0.0;
  double coordination_number = 0.0;  // 2 contact_count / particle_count
};

// What the aperture law saw, per flow pipe (each pipe is one contact).
struct CalibrationStressRecord {
  double uniform_normal_force_n = 0.0;  // on contacts not listed
  std::size_t listed_contact_forces = 0;
  std::size_t pipes_in_compression = 0;   // F > 0: a = a0 F0/(F + F0), proportional to a0
  std::size_t pipes_closed_unloaded = 0;  // F <= 0, no gap (or m = 0): a = a0
  std::size_t pipes_open = 0;             // F <= 0, g > 0, m > 0: a = a0 + m g, not prop. to a0
  std::size_t pipes_capped = 0;           // a = a_max at the calibrated a0
  double min_normal_force_n = 0.0;        // over the pipes
  double mean_normal_force_n = 0.0;
  double max_normal_force_n = 0.0;
  // No open and no capped pipe: k is proportional to a0^3 and one cube-root correction is exact.
  bool aperture_proportional_to_a0 = false;
};

struct CalibrationRecord {
  std::size_t target_index = 0;  // index into CalibrationSpec::target_permeabilities_m2
  double target_permeability_m2 = 0.0;

  // The result: a0, the permeability the permeameter measures with it, and its relative error.
  double residual_aperture_m = 0.0;
  double permeability_m2 = 0.0;
  double relative_error = 0.0;  // |k - k_target| / k_target
  bool converged = false;       // relative_error < tolerance
  // Permeameter solves (the first guess is iteration 1) and the a0 updates after it
  // (corrections = iterations - 1): 0 on a lattice, 1 when every aperture is proportional to a0.
  int iterations = 0;
  int corrections = 0;

  // The first guess: a0 from the affine estimate (docs/physics.md §1.3 (C1), evaluated on this
  // packing's pipes with the aperture law and stress state), and what the permeameter measured with
  // it.
  double first_guess_residual_aperture_m = 0.0;
  double first_guess_permeability_m2 = 0.0;
  double first_guess_relative_error = 0.0;

  CalibrationPackingStats packing;
  FluidSpec fluid;
  ApertureLawSpec aperture;  // residual_aperture_m = the result; F0, m, a_max as used
  CalibrationStressRecord stress;
  FlowAxis flow_axis = FlowAxis::kX;
  double pressure_drop_pa = 0.0;  // inlet - outlet
  double sample_length_m = 0.0;   // Darcy length at the result (scene_network.h)
  double sample_width_m = 0.0;    // Darcy width (scene_network.h)
};

// The record as named numbers sorted by name (flags as 0/1, the axis as 0 = x, 1 = y), the shape
// RunReport::metrics has, for a service to store without knowing the struct.
std::vector<std::pair<std::string, double>> CalibrationMetrics(const CalibrationRecord& record);

}  // namespace seep::core
