// core::SceneFields -> seep.v1.JobFields (see fields_codec.h): a field-for-field copy.
#include "codec/fields_codec.h"

#include <vector>

namespace seep::service {
namespace {

template <typename T, typename Repeated>
void Copy(const std::vector<T>& from, Repeated* to) {
  to->Clear();
  to->Add(from.begin(), from.end());
}

}  // namespace

void SceneFieldsToProto(const core::SceneFields& f, v1::JobFields* out) {
  Copy(f.particle_x, out->mutable_particle_x_m());
  Copy(f.particle_y, out->mutable_particle_y_m());
  Copy(f.particle_radius, out->mutable_particle_radius_m());
  Copy(f.domain_centroid_x, out->mutable_domain_centroid_x_m());
  Copy(f.domain_centroid_y, out->mutable_domain_centroid_y_m());
  Copy(f.domain_pressure, out->mutable_domain_pressure_pa());
  Copy(f.domain_apparent_volume, out->mutable_domain_apparent_volume_m2());
  Copy(f.domain_pore_volume, out->mutable_domain_pore_volume_m2());
  Copy(f.domain_loop_offsets, out->mutable_domain_loop_offsets());
  Copy(f.domain_loop_particles, out->mutable_domain_loop_particles());
  Copy(f.wall_vertex_x, out->mutable_wall_vertex_x_m());
  Copy(f.wall_vertex_y, out->mutable_wall_vertex_y_m());
  Copy(f.pipe_domain_a, out->mutable_pipe_domain_a());
  Copy(f.pipe_domain_b, out->mutable_pipe_domain_b());
  Copy(f.pipe_particle_i, out->mutable_pipe_particle_i());
  Copy(f.pipe_particle_j, out->mutable_pipe_particle_j());
  Copy(f.pipe_x0, out->mutable_pipe_x0_m());
  Copy(f.pipe_y0, out->mutable_pipe_y0_m());
  Copy(f.pipe_x1, out->mutable_pipe_x1_m());
  Copy(f.pipe_y1, out->mutable_pipe_y1_m());
  Copy(f.pipe_aperture, out->mutable_pipe_aperture_m());
  Copy(f.pipe_conductance, out->mutable_pipe_conductance());
  Copy(f.pipe_flow, out->mutable_pipe_flow_m2_per_s());
  out->set_analytic_kind(f.analytic_kind);
  Copy(f.domain_analytic_pressure, out->mutable_domain_analytic_pressure_pa());
  Copy(f.domain_axis_coordinate, out->mutable_domain_axis_coordinate_m());
  out->set_axis_length_m(f.axis_length);
  out->set_axis_name(f.axis_name);
}

}  // namespace seep::service
