#include "seep/core/scene/scene_network.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "seep/core/geometry/random_packing.h"

namespace seep::core {
namespace {

// Lattice disks touch exactly in theory but sit 1e-16 apart in floating point; a contact test
// tolerance well below any physical gap keeps them in contact.
constexpr double kRelativeContactTolerance = 1e-9;

struct PackingBuilder {
  Result<Packing> operator()(const LatticePackingSpec& s) const {
    const int nx = static_cast<int>(s.columns);
    const int ny = static_cast<int>(s.rows);
    return s.kind == LatticeKind::kSquare ? SquareLattice(nx, ny, s.radius_m)
                                          : HexLattice(nx, ny, s.radius_m);
  }
  Result<Packing> operator()(const RandomPackingSpec& s) const {
    RandomPackingOptions options;
    options.count = static_cast<std::int32_t>(s.particle_count);
    options.radius_min = s.min_radius_m;
    options.radius_max = s.max_radius_m;
    options.width = s.width_m;
    options.height = s.height_m;
    options.seed = s.seed;
    if (s.target_porosity > 0.0) {
      options.target = RandomPackingOptions::Target::kPorosity;
      options.porosity = s.target_porosity;
    } else {
      options.target = RandomPackingOptions::Target::kCoordination;
      options.coordination = s.target_coordination;
    }
    SEEP_ASSIGN_OR_RETURN(RandomPacking random, GenerateRandomPacking(options));
    return std::move(random.packing);
  }
  Result<Packing> operator()(const ParticleListSpec& s) const {
    Packing p;
    p.Reserve(s.x_m.size());
    for (std::size_t i = 0; i < s.x_m.size(); ++i) p.Add(s.x_m[i], s.y_m[i], s.radius_m[i]);
    SEEP_RETURN_IF_ERROR(ValidatePacking(p));
    return p;
  }
};

double AxisCoordinate(FlowAxis axis, const Packing& p, std::size_t i) {
  return axis == FlowAxis::kX ? p.x[i] : p.y[i];
}

}  // namespace

Result<Packing> BuildScenePacking(const PackingSpec& spec) {
  return std::visit(PackingBuilder{}, spec.source);
}

Result<SceneNetwork> BuildSceneNetwork(const SceneSpec& scene) {
  SceneNetwork net;
  SEEP_ASSIGN_OR_RETURN(net.packing, BuildScenePacking(scene.packing));
  const Packing& p = net.packing;
  const std::size_t n = p.size();
  double radius_sum = 0.0;
  for (double r : p.radius) radius_sum += r;
  net.mean_radius_m = radius_sum / static_cast<double>(n);

  const double max_gap =
      scene.packing.contact_gap_m + kRelativeContactTolerance * net.mean_radius_m;
  ContactDetector contact_detector;
  SEEP_RETURN_IF_ERROR(contact_detector.Detect(p, max_gap, &net.contacts));
  DomainDetector domain_detector;
  SEEP_RETURN_IF_ERROR(domain_detector.Detect(p, net.contacts, {max_gap}, &net.domains));
  const DomainNetwork& d = net.domains;
  const std::size_t num_domains = d.num_domains();
  if (num_domains == 0) {
    return FailedPrecondition(
        "scene.packing: the contact graph encloses no domain (no closed loop of touching "
        "particles); raise packing.contact_gap_m or use a denser packing");
  }

  // The sample's ends along the axis, from the particles' surfaces.
  const FlowAxis axis = scene.boundary.axis;
  double low = std::numeric_limits<double>::infinity();
  double high = -low;
  for (std::size_t i = 0; i < n; ++i) {
    low = std::min(low, AxisCoordinate(axis, p, i) - p.radius[i]);
    high = std::max(high, AxisCoordinate(axis, p, i) + p.radius[i]);
  }
  net.length_m = high - low;
  double centre_low = std::numeric_limits<double>::infinity();
  double centre_high = -centre_low;
  for (std::int32_t particle : d.loop_particles) {
    centre_low = std::min(centre_low, AxisCoordinate(axis, p, static_cast<std::size_t>(particle)));
    centre_high =
        std::max(centre_high, AxisCoordinate(axis, p, static_cast<std::size_t>(particle)));
  }
  double domain_area = 0.0;
  for (double v : d.apparent_volume) domain_area += v;
  net.width_m = centre_high > centre_low ? domain_area / (centre_high - centre_low) : 0.0;

  FlowNetworkData data;
  const std::size_t nodes = num_domains + 2;
  net.inlet_node = static_cast<std::int32_t>(num_domains);
  net.outlet_node = static_cast<std::int32_t>(num_domains + 1);
  data.apparent_volume.assign(d.apparent_volume.begin(), d.apparent_volume.end());
  data.pore_volume.assign(d.pore_volume.begin(), d.pore_volume.end());
  data.apparent_volume.resize(nodes, 0.0);
  data.pore_volume.resize(nodes, 0.0);
  data.pressure.assign(nodes, scene.boundary.initial_pressure_pa);
  data.pressure[static_cast<std::size_t>(net.inlet_node)] = scene.boundary.inlet_pressure_pa;
  data.pressure[static_cast<std::size_t>(net.outlet_node)] = scene.boundary.outlet_pressure_pa;
  data.role.assign(nodes, DomainRole::kFree);
  data.role[static_cast<std::size_t>(net.inlet_node)] = DomainRole::kFixedPressure;
  data.role[static_cast<std::size_t>(net.outlet_node)] = DomainRole::kFixedPressure;
  data.source_rate.assign(nodes, 0.0);

  std::vector<double> gaps;
  auto add_pipe = [&](std::int32_t a, std::int32_t b, std::int32_t contact, double length) {
    data.pipe_domain_a.push_back(a);
    data.pipe_domain_b.push_back(b);
    data.pipe_length.push_back(length);
    gaps.push_back(net.contacts.gap[static_cast<std::size_t>(contact)]);
  };
  for (std::size_t k = 0; k < d.num_pipes(); ++k) {
    add_pipe(d.pipe_domain_a[k], d.pipe_domain_b[k], d.pipe_contact[k], d.pipe_length[k]);
  }
  // Edge layer: particles whose extreme coordinate lies within one mean radius of the end.
  const double layer = net.mean_radius_m * (1.0 + 1e-9);
  for (std::size_t k = 0; k < d.num_boundary_pipes(); ++k) {
    if (d.outer_host_domain[static_cast<std::size_t>(d.boundary_pipe_outer_face[k])] >= 0) continue;
    const auto c = static_cast<std::size_t>(d.boundary_pipe_contact[k]);
    const auto i = static_cast<std::size_t>(net.contacts.i[c]);
    const auto j = static_cast<std::size_t>(net.contacts.j[c]);
    const bool at_inlet = AxisCoordinate(axis, p, i) - p.radius[i] <= low + layer &&
                          AxisCoordinate(axis, p, j) - p.radius[j] <= low + layer;
    const bool at_outlet = AxisCoordinate(axis, p, i) + p.radius[i] >= high - layer &&
                           AxisCoordinate(axis, p, j) + p.radius[j] >= high - layer;
    if (at_inlet == at_outlet) continue;  // a side wall, or a sample one particle long
    add_pipe(d.boundary_pipe_domain[k], at_inlet ? net.inlet_node : net.outlet_node,
             d.boundary_pipe_contact[k], d.boundary_pipe_length[k]);
    ++(at_inlet ? net.inlet_pipes : net.outlet_pipes);
  }
  if (net.inlet_pipes == 0 || net.outlet_pipes == 0) {
    return FailedPrecondition(fmt::format(
        "scene.boundary.axis: the sample has {} inlet and {} outlet pipes; both ends need hull "
        "contacts in their edge layer (is the packing connected from end to end?)",
        net.inlet_pipes, net.outlet_pipes));
  }

  // A rigid, unloaded packing: no contact force, so a = a0 + m g (eq. 3).
  ApertureLaw law;
  law.residual_aperture = scene.aperture.residual_aperture_m;
  law.reference_force =
      scene.aperture.reference_force_n > 0.0 ? scene.aperture.reference_force_n : 1.0;
  law.gap_multiplier = scene.aperture.gap_multiplier;
  if (scene.aperture.max_aperture_m > 0.0) law.max_aperture = scene.aperture.max_aperture_m;
  const std::size_t num_pipes = data.pipe_length.size();
  const std::vector<double> no_force(num_pipes, 0.0);
  data.pipe_aperture.assign(num_pipes, 0.0);
  data.pipe_conductance.assign(num_pipes, 0.0);
  SEEP_RETURN_IF_ERROR(FillAperturesAndConductances(law, scene.fluid.viscosity_pa_s, no_force, gaps,
                                                    data.pipe_length, data.pipe_aperture,
                                                    data.pipe_conductance));
  SEEP_ASSIGN_OR_RETURN(net.flow, FlowNetwork::Create(std::move(data)));
  return net;
}

}  // namespace seep::core
