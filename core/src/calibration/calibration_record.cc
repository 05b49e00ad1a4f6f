// CalibrationMetrics (calibration_record.h): a record as sorted named numbers.
#include "seep/core/calibration/calibration_record.h"

#include <map>

namespace seep::core {

std::vector<std::pair<std::string, double>> CalibrationMetrics(const CalibrationRecord& r) {
  auto count = [](std::size_t n) { return static_cast<double>(n); };
  std::map<std::string, double> m;
  m["target_index"] = count(r.target_index);
  m["target_permeability_m2"] = r.target_permeability_m2;
  m["residual_aperture_m"] = r.residual_aperture_m;
  m["permeability_m2"] = r.permeability_m2;
  m["relative_error"] = r.relative_error;
  m["converged"] = r.converged ? 1.0 : 0.0;
  m["iterations"] = r.iterations;
  m["corrections"] = r.corrections;
  m["first_guess_residual_aperture_m"] = r.first_guess_residual_aperture_m;
  m["first_guess_permeability_m2"] = r.first_guess_permeability_m2;
  m["first_guess_relative_error"] = r.first_guess_relative_error;
  m["particle_count"] = count(r.packing.particle_count);
  m["contact_count"] = count(r.packing.contact_count);
  m["domain_count"] = count(r.packing.domain_count);
  m["pipe_count"] = count(r.packing.pipe_count);
  m["porosity_2d"] = r.packing.porosity_2d;
  m["mean_radius_m"] = r.packing.mean_radius_m;
  m["radius_std_dev_m"] = r.packing.radius_std_dev_m;
  m["min_radius_m"] = r.packing.min_radius_m;
  m["max_radius_m"] = r.packing.max_radius_m;
  m["coordination_number"] = r.packing.coordination_number;
  m["viscosity_pa_s"] = r.fluid.viscosity_pa_s;
  m["bulk_modulus_pa"] = r.fluid.bulk_modulus_pa;
  m["reference_force_n"] = r.aperture.reference_force_n;
  m["gap_multiplier"] = r.aperture.gap_multiplier;
  m["max_aperture_m"] = r.aperture.max_aperture_m;
  m["uniform_normal_force_n"] = r.stress.uniform_normal_force_n;
  m["listed_contact_forces"] = count(r.stress.listed_contact_forces);
  m["pipes_in_compression"] = count(r.stress.pipes_in_compression);
  m["pipes_closed_unloaded"] = count(r.stress.pipes_closed_unloaded);
  m["pipes_open"] = count(r.stress.pipes_open);
  m["pipes_capped"] = count(r.stress.pipes_capped);
  m["min_normal_force_n"] = r.stress.min_normal_force_n;
  m["mean_normal_force_n"] = r.stress.mean_normal_force_n;
  m["max_normal_force_n"] = r.stress.max_normal_force_n;
  m["aperture_proportional_to_a0"] = r.stress.aperture_proportional_to_a0 ? 1.0 : 0.0;
  m["flow_axis"] = r.flow_axis == FlowAxis::kX ? 0.0 : 1.0;
  m["pressure_drop_pa"] = r.pressure_drop_pa;
  m["sample_length_m"] = r.sample_length_m;
  m["sample_width_m"] = r.sample_width_m;
  return {m.begin(), m.end()};
}

}  // namespace seep::core
