// CalibrationNetwork (calibration_network.h): pipe mapping, aperture fill, Darcy k and the affine
// estimate.
#include "calibration_network.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "seep/core/flow/flow_diagnostics.h"

namespace seep::core::calibration_internal {
namespace {

struct ListedForce {
  std::int32_t i;
  std::int32_t j;
  double force;
  bool operator<(const ListedForce& o) const { return i != o.i ? i < o.i : j < o.j; }
};

}  // namespace

Result<CalibrationNetwork> CalibrationNetwork::Build(const CalibrationSpec& spec) {
  SceneSpec scene = spec.scene;
  // Any a0 builds the same topology; the apertures are rewritten before every solve.
  scene.aperture.residual_aperture_m =
      scene.aperture.max_aperture_m > 0.0 ? scene.aperture.max_aperture_m : 1e-5;
  scene.solver.kind = SolverKind::kSteady;
  SEEP_ASSIGN_OR_RETURN(SteadyStateSolver solver, SteadyStateSolver::Create({}));
  CalibrationNetwork cal(std::move(solver));
  SEEP_ASSIGN_OR_RETURN(cal.net_, BuildSceneNetwork(scene));
  cal.law_.reference_force =
      scene.aperture.reference_force_n > 0.0 ? scene.aperture.reference_force_n : 1.0;
  cal.law_.gap_multiplier = scene.aperture.gap_multiplier;
  if (scene.aperture.max_aperture_m > 0.0) cal.law_.max_aperture = scene.aperture.max_aperture_m;
  cal.viscosity_ = scene.fluid.viscosity_pa_s;
  cal.pressure_drop_ = scene.boundary.inlet_pressure_pa - scene.boundary.outlet_pressure_pa;
  SEEP_RETURN_IF_ERROR(cal.MapPipes(spec));
  cal.ComputeStatistics(spec);
  return cal;
}

// The flow network's pipes and their contacts come from the scene network; a pipe's offset is
// the axis distance its flow crosses: between the two domain centroids inside the sample, from
// the domain's centroid to its reflected image for a reservoir pipe.
Status CalibrationNetwork::MapPipes(const CalibrationSpec& spec) {
  const Packing& p = net_.packing;
  const DomainNetwork& d = net_.domains;
  const FlowNetwork& flow = net_.flow;
  const FlowAxis axis = spec.scene.boundary.axis;
  const std::vector<double>& centroid = axis == FlowAxis::kX ? d.centroid_x : d.centroid_y;
  if (net_.pipe_contact.size() != flow.num_pipes()) {
    return Internal(fmt::format("calibration: {} pipe contacts for {} pipes",
                                net_.pipe_contact.size(), flow.num_pipes()));
  }
  const std::vector<std::int32_t>& contact = net_.pipe_contact;
  offset_.assign(flow.num_pipes(), 0.0);
  for (std::size_t k = 0; k < d.num_pipes(); ++k) {
    offset_[k] = centroid[static_cast<std::size_t>(d.pipe_domain_b[k])] -
                 centroid[static_cast<std::size_t>(d.pipe_domain_a[k])];
  }
  for (const ReservoirPipe& r : net_.reservoir_pipes) {
    const auto host = static_cast<std::size_t>(flow.pipe_domain_a()[r.pipe]);
    // q = C (P_b - P_a) flows from the reservoir b into a: the offset runs from a to b's image.
    offset_[r.pipe] = r.image_m - centroid[host];
    end_pipe_.push_back(r.pipe);
    end_inlet_.push_back(r.inlet ? 1 : 0);
    end_image_.push_back(r.image_m);
  }

  // Normal forces by contact, from the stress spec.
  std::vector<ListedForce> listed;
  listed.reserve(spec.stress.contact_forces.size());
  for (std::size_t k = 0; k < spec.stress.contact_forces.size(); ++k) {
    const ContactForceSpec& f = spec.stress.contact_forces[k];
    const auto [i, j] = std::minmax(f.particle_i, f.particle_j);
    if (static_cast<std::size_t>(j) >= p.size()) {
      return InvalidArgument(fmt::format(
          "calibration.stress.contact_forces[{}]: particle id {} is out of range (the packing "
          "has {} particles)",
          k, j, p.size()));
    }
    listed.push_back({i, j, f.normal_force_n});
  }
  std::sort(listed.begin(), listed.end());
  // Every listed pair must be a contact of the packing, or its force would be silently lost.
  for (std::size_t k = 0; k < spec.stress.contact_forces.size(); ++k) {
    const ContactForceSpec& f = spec.stress.contact_forces[k];
    const auto [i, j] = std::minmax(f.particle_i, f.particle_j);
    bool found = false;
    for (std::size_t lo = 0, hi = net_.contacts.size(); lo < hi && !found;) {
      const std::size_t mid = lo + (hi - lo) / 2;
      const std::int32_t ci = net_.contacts.i[mid];
      const std::int32_t cj = net_.contacts.j[mid];
      if (ci == i && cj == j) {
        found = true;
      } else if (ci < i || (ci == i && cj < j)) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    if (!found) {
      return InvalidArgument(fmt::format(
          "calibration.stress.contact_forces[{}]: particles {} and {} are not in contact (gap > "
          "scene.packing.contact_gap_m)",
          k, i, j));
    }
  }
  force_.resize(contact.size());
  gap_.resize(contact.size());
  for (std::size_t k = 0; k < contact.size(); ++k) {
    const auto c = static_cast<std::size_t>(contact[k]);
    const ListedForce key{net_.contacts.i[c], net_.contacts.j[c], 0.0};
    const auto it = std::lower_bound(listed.begin(), listed.end(), key);
    force_[k] = it != listed.end() && it->i == key.i && it->j == key.j
                    ? it->force
                    : spec.stress.uniform_normal_force_n;
    gap_[k] = net_.contacts.gap[c];
  }
  scratch_.resize(contact.size());
  return Status::Ok();
}

void CalibrationNetwork::ComputeStatistics(const CalibrationSpec& spec) {
  const Packing& p = net_.packing;
  CalibrationPackingStats& s = packing_stats_;
  s.particle_count = p.size();
  s.contact_count = net_.contacts.size();
  s.domain_count = net_.domains.num_domains();
  s.pipe_count = net_.flow.num_pipes();
  double pore = 0.0;
  double apparent = 0.0;
  for (std::size_t k = 0; k < net_.domains.num_domains(); ++k) {
    pore += net_.domains.pore_volume[k];
    apparent += net_.domains.apparent_volume[k];
  }
  s.porosity_2d = apparent > 0.0 ? pore / apparent : 0.0;
  s.mean_radius_m = net_.mean_radius_m;
  s.min_radius_m = *std::min_element(p.radius.begin(), p.radius.end());
  s.max_radius_m = *std::max_element(p.radius.begin(), p.radius.end());
  double variance = 0.0;
  for (double r : p.radius) variance += (r - s.mean_radius_m) * (r - s.mean_radius_m);
  s.radius_std_dev_m = std::sqrt(variance / static_cast<double>(p.size()));
  s.coordination_number =
      2.0 * static_cast<double>(s.contact_count) / static_cast<double>(s.particle_count);

  CalibrationStressRecord& t = stress_;
  t.uniform_normal_force_n = spec.stress.uniform_normal_force_n;
  t.listed_contact_forces = spec.stress.contact_forces.size();
  double force_sum = 0.0;
  t.min_normal_force_n = std::numeric_limits<double>::infinity();
  t.max_normal_force_n = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < force_.size(); ++k) {
    const double f = force_[k];
    force_sum += f;
    t.min_normal_force_n = std::min(t.min_normal_force_n, f);
    t.max_normal_force_n = std::max(t.max_normal_force_n, f);
    if (f > 0.0) {
      ++t.pipes_in_compression;
    } else if (gap_[k] > 0.0 && law_.gap_multiplier > 0.0) {
      ++t.pipes_open;
    } else {
      ++t.pipes_closed_unloaded;
    }
  }
  t.mean_normal_force_n = force_.empty() ? 0.0 : force_sum / static_cast<double>(force_.size());
  if (force_.empty()) t.min_normal_force_n = t.max_normal_force_n = 0.0;
}

void CalibrationNetwork::FillApertures(double a0, std::span<double> aperture) const {
  ApertureLaw law = law_;
  law.residual_aperture = a0;
  for (std::size_t k = 0; k < force_.size(); ++k) aperture[k] = Aperture(law, force_[k], gap_[k]);
}

std::size_t CalibrationNetwork::CappedPipes(double a0) const {
  if (!std::isfinite(law_.max_aperture)) return 0;
  FillApertures(a0, scratch_);
  return static_cast<std::size_t>(std::count(scratch_.begin(), scratch_.end(), law_.max_aperture));
}

// Reservoir positions as in scene_network.cc: the weight-averaged images per end.
double CalibrationNetwork::LengthFromWeights(std::span<const double> weight) const {
  double image_sum[2] = {0.0, 0.0};
  double weight_sum[2] = {0.0, 0.0};
  for (std::size_t e = 0; e < end_pipe_.size(); ++e) {
    const int side = end_inlet_[e] != 0 ? 0 : 1;
    const double w = weight[end_pipe_[e]];
    image_sum[side] += w * end_image_[e];
    weight_sum[side] += w;
  }
  return image_sum[1] / weight_sum[1] - image_sum[0] / weight_sum[0];
}

double CalibrationNetwork::SampleLength(double a0) const {
  FillApertures(a0, scratch_);
  const std::span<const double> length = net_.flow.pipe_length();
  for (std::size_t k = 0; k < scratch_.size(); ++k) {
    scratch_[k] = PipeConductance(scratch_[k], viscosity_, length[k]);
  }
  return LengthFromWeights(scratch_);
}

double CalibrationNetwork::AffinePermeability(double a0) const {
  FillApertures(a0, scratch_);
  const std::span<const double> length = net_.flow.pipe_length();
  double sum = 0.0;
  for (std::size_t k = 0; k < scratch_.size(); ++k) {
    // mu C_p: the cubic law without the viscosity, which cancels in k.
    scratch_[k] = PipeConductance(scratch_[k], 1.0, length[k]);
    sum += scratch_[k] * offset_[k] * offset_[k];
  }
  return sum / (net_.width_m * LengthFromWeights(scratch_));
}

Result<double> CalibrationNetwork::MeasurePermeability(double a0) {
  FillApertures(a0, scratch_);
  SEEP_RETURN_IF_ERROR(net_.flow.SetApertures(scratch_, viscosity_));
  SEEP_ASSIGN_OR_RETURN(const SteadyStateReport report, solver_.Solve(net_.flow));
  (void)report;
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(net_.flow);
  const double inflow = NodeInflow(fluxes, net_.inlet_node);
  const double outflow = -NodeInflow(fluxes, net_.outlet_node);
  const double length = LengthFromWeights(net_.flow.pipe_conductance());
  return DarcyPermeability(viscosity_, 0.5 * (inflow + outflow), length, net_.width_m,
                           pressure_drop_);
}

}  // namespace seep::core::calibration_internal
