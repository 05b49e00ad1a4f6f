#include "seep/core/network/scene_network.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "seep/core/flow/storage_volume.h"
#include "seep/core/geometry/random_packing.h"
#include "seep/core/network/boundary_regions.h"
#include "seep/core/network/scene_walls.h"

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

// A rigid, unloaded packing: no contact force, so a = a0 + m g (eq. 3).
Status FillConductances(const SceneSpec& scene, const std::vector<double>& gaps,
                        FlowNetworkData& data) {
  const ApertureLaw law = SceneApertureLaw(scene);
  const std::size_t num_pipes = data.pipe_length.size();
  const std::vector<double> no_force(num_pipes, 0.0);
  data.pipe_aperture.assign(num_pipes, 0.0);
  data.pipe_conductance.assign(num_pipes, 0.0);
  return FillAperturesAndConductances(law, scene.fluid.viscosity_pa_s, no_force, gaps,
                                      data.pipe_length, data.pipe_aperture, data.pipe_conductance);
}

// The flow network of `data`, the boundary built: the boundary regions go on top of it (their
// roles before the network is made, their values after), so every boundary kind, at set-up and
// at every re-detection, gets them the same way.
Status CreateFlow(const SceneSpec& scene, FlowNetworkData data, SceneNetwork& net) {
  AssignBoundaryRegions(scene, net.domains, &data, &net.regions);
  SEEP_ASSIGN_OR_RETURN(net.flow, FlowNetwork::Create(std::move(data)));
  return SetRegionConditions(scene, &net);
}

// Keeps the particles whose centre lies in [well_radius, outer_radius] of the centre of the
// particles' bounding box.
Status CutAnnulus(const RadialBoundarySpec& radial, SceneNetwork& net) {
  const Packing& full = net.packing;
  const auto [x_lo, x_hi] = std::minmax_element(full.x.begin(), full.x.end());
  const auto [y_lo, y_hi] = std::minmax_element(full.y.begin(), full.y.end());
  net.well_x_m = 0.5 * (*x_lo + *x_hi);
  net.well_y_m = 0.5 * (*y_lo + *y_hi);
  Packing cut;
  cut.Reserve(full.size());
  std::size_t in_well = 0;
  for (std::size_t i = 0; i < full.size(); ++i) {
    const double r = std::hypot(full.x[i] - net.well_x_m, full.y[i] - net.well_y_m);
    if (r < radial.well_radius_m) {
      ++in_well;
    } else if (r <= radial.outer_radius_m) {
      cut.Add(full.x[i], full.y[i], full.radius[i]);
    }
  }
  if (in_well == 0) {
    return InvalidArgument(fmt::format(
        "scene.boundary.radial.well_radius_m: no particle lies within {} m of the sample centre "
        "({}, {}); the well removes nothing",
        radial.well_radius_m, net.well_x_m, net.well_y_m));
  }
  if (cut.size() < 3) {
    return InvalidArgument(
        fmt::format("scene.boundary.radial: only {} particles lie between well_radius_m = {} and "
                    "outer_radius_m = {} of the sample centre",
                    cut.size(), radial.well_radius_m, radial.outer_radius_m));
  }
  net.packing = std::move(cut);
  return Status::Ok();
}

// A loop vertex's position at detection: a particle's centre or a wall vertex.
void LoopVertex(const Packing& p, const DomainNetwork& d, std::int32_t id, double* x, double* y) {
  if (d.walls.IsWallVertex(id)) {
    const auto v = static_cast<std::size_t>(id - d.walls.num_particles);
    *x = d.walls.vertex_x[v];
    *y = d.walls.vertex_y[v];
    return;
  }
  *x = p.x[static_cast<std::size_t>(id)];
  *y = p.y[static_cast<std::size_t>(id)];
}

// Crossing-number test of a point against domain d's loop of particle centres (and wall vertices).
bool LoopContains(const Packing& p, const DomainNetwork& d, std::size_t domain, double x,
                  double y) {
  bool inside = false;
  const auto begin = static_cast<std::size_t>(d.loop_offsets[domain]);
  const auto end = static_cast<std::size_t>(d.loop_offsets[domain + 1]);
  for (std::size_t k = begin; k < end; ++k) {
    double xi = 0.0, yi = 0.0, xj = 0.0, yj = 0.0;
    LoopVertex(p, d, d.loop_particles[k], &xi, &yi);
    LoopVertex(p, d, d.loop_particles[k + 1 < end ? k + 1 : begin], &xj, &yj);
    if ((yi > y) != (yj > y) && x < xi + (y - yi) * (xj - xi) / (yj - yi)) inside = !inside;
  }
  return inside;
}

// A pipe of the flow network across detection contact `contact` (a wall edge included), with
// its gap for the conductance and its contact for later aperture updates.
void AddPipe(SceneNetwork& net, FlowNetworkData& data, std::vector<double>& gaps, std::int32_t a,
             std::int32_t b, std::int32_t contact, double length) {
  data.pipe_domain_a.push_back(a);
  data.pipe_domain_b.push_back(b);
  data.pipe_length.push_back(length);
  gaps.push_back(DetectionContactGap(net, contact));
  net.pipe_contact.push_back(contact);
}

// The part every boundary shares: the detected domains, free at the initial pressure, then
// `reservoirs` nodes without volume (free until the caller fixes them), and the interior pipes.
FlowNetworkData DomainsAndInteriorPipes(const SceneSpec& scene, SceneNetwork& net,
                                        std::size_t reservoirs, std::vector<double>& gaps) {
  const DomainNetwork& d = net.domains;
  const std::size_t nodes = d.num_domains() + reservoirs;
  FlowNetworkData data;
  // Reserved for what the callers add (a node per drained wall; a pipe per boundary pipe at
  // most), so that no array doubles its capacity, and holds it for the run, by growing.
  const std::size_t max_nodes = nodes + net.walls.size();
  for (std::vector<double>* v :
       {&data.apparent_volume, &data.pore_volume, &data.pressure, &data.source_rate}) {
    v->reserve(max_nodes);
  }
  data.role.reserve(max_nodes);
  const std::size_t max_pipes = d.num_pipes() + d.num_boundary_pipes();
  data.pipe_domain_a.reserve(max_pipes);
  data.pipe_domain_b.reserve(max_pipes);
  data.pipe_length.reserve(max_pipes);
  gaps.reserve(max_pipes);
  net.pipe_contact.reserve(net.pipe_contact.size() + max_pipes);
  data.apparent_volume.assign(d.apparent_volume.begin(), d.apparent_volume.end());
  data.pore_volume.assign(d.pore_volume.begin(), d.pore_volume.end());
  data.apparent_volume.resize(nodes, 0.0);
  data.pore_volume.resize(nodes, 0.0);
  data.pressure.assign(nodes, scene.boundary.initial_pressure_pa);
  data.role.assign(nodes, DomainRole::kFree);
  data.source_rate.assign(nodes, 0.0);
  for (std::size_t k = 0; k < d.num_pipes(); ++k) {
    AddPipe(net, data, gaps, d.pipe_domain_a[k], d.pipe_domain_b[k], d.pipe_contact[k],
            d.pipe_length[k]);
  }
  return data;
}

// Whether boundary pipe k of the detection lies on a wall (a stretch, or a foot facing an open
// side): the walls decide its flow, not the linear or radial rules.
bool OnWall(const DomainNetwork& d, std::size_t k) {
  return d.walls.IsWallEdge(d.boundary_pipe_contact[k]);
}

// The reservoir nodes of the drained walls (after the nodes already in `data`) and the pipes of
// their stretches. A stretch pipe keeps the scene's conductance C = c_drain x its length: it is
// stored as the aperture a0 of the scene's law over the length a0^3 / (12 mu C), so that every
// re-evaluation of the cubic law (a restore, SetApertures) gives the same C; its pipe_contact is
// -1 so no aperture update touches it.
void AddDrainedWalls(const SceneSpec& scene, SceneNetwork& net, FlowNetworkData& data,
                     std::vector<double>& gaps) {
  const DomainNetwork& d = net.domains;
  const auto* walls = FindEffect<WallsEffectSpec>(scene);
  net.wall_node.assign(net.walls.size(), -1);
  if (walls == nullptr) return;
  for (std::size_t w = 0; w < net.walls.size(); ++w) {
    const auto& drain = walls->walls[w].drain;
    if (!drain) continue;
    net.wall_node[w] = static_cast<std::int32_t>(data.pressure.size());
    data.apparent_volume.push_back(0.0);
    data.pore_volume.push_back(0.0);
    data.pressure.push_back(drain->pressure_pa);
    data.role.push_back(DomainRole::kFixedPressure);
    data.source_rate.push_back(0.0);
  }
  const double a0 = scene.aperture.residual_aperture_m;
  for (std::size_t k = 0; k < d.num_boundary_pipes(); ++k) {
    if (!OnWall(d, k)) continue;
    const std::size_t e = d.walls.Edge(d.boundary_pipe_contact[k]);
    if (d.walls.edge_particle[e] >= 0) continue;  // a foot facing an open side: no flow
    const auto wall = static_cast<std::size_t>(d.walls.edge_wall[e]);
    if (net.wall_node[wall] < 0) continue;  // impermeable
    const double conductance = WallDrainConductance(scene, wall, d.walls.edge_gap[e]);
    if (!(conductance > 0.0)) continue;  // a stretch of zero length
    data.pipe_domain_a.push_back(d.boundary_pipe_domain[k]);
    data.pipe_domain_b.push_back(net.wall_node[wall]);
    data.pipe_length.push_back(a0 * a0 * a0 / (12.0 * scene.fluid.viscosity_pa_s * conductance));
    gaps.push_back(0.0);
    net.pipe_contact.push_back(-1);
  }
}

}  // namespace

std::optional<double> WellPressure(const SceneNetwork& net) {
  const auto pressure = net.flow.pressure();
  if (net.well_domain >= 0) return pressure[static_cast<std::size_t>(net.well_domain)];
  if (net.outer_node >= 0) return pressure[static_cast<std::size_t>(net.outer_node)];
  return std::nullopt;
}

double WallDrainConductance(const SceneSpec& scene, std::size_t wall, double length) {
  const auto* walls = FindEffect<WallsEffectSpec>(scene);
  if (walls == nullptr || wall >= walls->walls.size()) return 0.0;
  const auto& drain = walls->walls[wall].drain;
  return drain ? drain->conductance_m_per_pa_s * length : 0.0;
}

namespace {

Status ConnectRadialBoundary(const SceneSpec& scene, SceneNetwork& net) {
  const RadialBoundarySpec& radial = *scene.boundary.radial;
  const Packing& p = net.packing;
  const DomainNetwork& d = net.domains;
  const std::size_t num_domains = d.num_domains();
  // The well: the smallest domain whose loop encloses the sample centre.
  for (std::size_t k = 0; k < num_domains; ++k) {
    if (!LoopContains(p, d, k, net.well_x_m, net.well_y_m)) continue;
    if (net.well_domain < 0 ||
        d.apparent_volume[k] < d.apparent_volume[static_cast<std::size_t>(net.well_domain)]) {
      net.well_domain = static_cast<std::int32_t>(k);
    }
  }
  if (net.well_domain < 0 && !net.well_may_vanish) {
    return FailedPrecondition(fmt::format(
        "scene.boundary.radial.well_radius_m: the particles around the hole of radius {} m do "
        "not close a loop around it (no well domain); lower well_radius_m or use a denser "
        "packing",
        radial.well_radius_m));
  }

  std::vector<double> gaps;
  FlowNetworkData data = DomainsAndInteriorPipes(scene, net, 1, gaps);
  net.outer_node = static_cast<std::int32_t>(num_domains);
  if (net.well_domain >= 0) {
    const auto well = static_cast<std::size_t>(net.well_domain);
    data.pressure[well] = radial.well_pressure_pa;
    data.role[well] = DomainRole::kFixedPressure;
  }
  data.pressure[num_domains] = radial.outer_pressure_pa;
  data.role[num_domains] = DomainRole::kFixedPressure;
  // Every contact of a top-level outer loop drains into the outer reservoir. The reservoir's
  // radius is the conductance-weighted mean distance of the images of the interior centroids
  // reflected through the contact points (as for the linear ends, see the header).
  std::vector<double> image_radius;
  const std::size_t first_outer_pipe = data.pipe_length.size();
  for (std::size_t k = 0; k < d.num_boundary_pipes(); ++k) {
    if (d.outer_host_domain[static_cast<std::size_t>(d.boundary_pipe_outer_face[k])] >= 0) continue;
    if (OnWall(d, k)) continue;
    const auto host = static_cast<std::size_t>(d.boundary_pipe_domain[k]);
    AddPipe(net, data, gaps, d.boundary_pipe_domain[k], net.outer_node, d.boundary_pipe_contact[k],
            d.boundary_pipe_length[k]);
    image_radius.push_back(
        std::hypot(2.0 * d.boundary_pipe_x[k] - d.centroid_x[host] - net.well_x_m,
                   2.0 * d.boundary_pipe_y[k] - d.centroid_y[host] - net.well_y_m));
    ++net.outer_pipes;
  }
  if (net.outer_pipes == 0 && net.walls.empty()) {
    return FailedPrecondition(
        "scene.boundary.radial.outer_radius_m: the cut sample has no hull contact to connect to "
        "the outer reservoir");
  }
  AddDrainedWalls(scene, net, data, gaps);
  SEEP_RETURN_IF_ERROR(FillConductances(scene, gaps, data));
  double weighted = 0.0;
  double weight = 0.0;
  for (std::size_t k = 0; k < image_radius.size(); ++k) {
    const double c = data.pipe_conductance[first_outer_pipe + k];
    weighted += c * image_radius[k];
    weight += c;
  }
  net.outer_reservoir_radius_m = weight > 0.0 ? weighted / weight : 0.0;
  for (std::size_t k = 0; k < d.num_boundary_pipes() && net.well_domain >= 0; ++k) {
    if (OnWall(d, k) && d.boundary_pipe_domain[k] == net.well_domain) net.well_on_wall = true;
  }
  return CreateFlow(scene, std::move(data), net);
}

}  // namespace

Result<Packing> BuildScenePacking(const PackingSpec& spec) {
  return std::visit(PackingBuilder{}, spec.source);
}

StorageModel RunStorage(const SceneSpec& scene, const FlowNetwork& flow) {
  StorageModel storage = SceneStorage(scene);
  if (scene.solver.storage_floor_fraction <= 0.0) return storage;
  double sum = 0.0;
  std::size_t counted = 0;
  const auto role = flow.role();
  for (std::size_t d = 0; d < flow.num_domains(); ++d) {
    if (role[d] == DomainRole::kFixedPressure) continue;
    sum += StorageVolumeOf(flow, storage, d);
    ++counted;
  }
  if (counted > 0) {
    storage.floor_m2 = scene.solver.storage_floor_fraction * (sum / static_cast<double>(counted));
  }
  return storage;
}

ApertureLaw SceneApertureLaw(const SceneSpec& scene) {
  ApertureLaw law;
  law.residual_aperture = scene.aperture.residual_aperture_m;
  law.reference_force =
      scene.aperture.reference_force_n > 0.0 ? scene.aperture.reference_force_n : 1.0;
  law.gap_multiplier = scene.aperture.gap_multiplier;
  if (scene.aperture.max_aperture_m > 0.0) law.max_aperture = scene.aperture.max_aperture_m;
  return law;
}

double DetectionContactGap(const SceneNetwork& net, std::int32_t contact) {
  const DomainWalls& walls = net.domains.walls;
  if (walls.IsWallEdge(contact)) return walls.edge_gap[walls.Edge(contact)];
  return net.contacts.gap[static_cast<std::size_t>(contact)];
}

double SceneContactGap(const SceneSpec& scene, double mean_radius_m) {
  return scene.packing.contact_gap_m + kRelativeContactTolerance * mean_radius_m;
}

Result<SceneNetwork> BuildSceneNetwork(const SceneSpec& scene) {
  SceneNetwork net;
  SEEP_ASSIGN_OR_RETURN(net.packing, BuildScenePacking(scene.packing));
  if (scene.boundary.radial) SEEP_RETURN_IF_ERROR(CutAnnulus(*scene.boundary.radial, net));
  const Packing& p = net.packing;
  double radius_sum = 0.0;
  for (double r : p.radius) radius_sum += r;
  net.mean_radius_m = radius_sum / static_cast<double>(p.size());
  net.weight_origin_x_m = p.x[0];
  net.weight_origin_y_m = p.y[0];
  ContactDetector contact_detector;
  const double max_gap = SceneContactGap(scene, net.mean_radius_m);
  SEEP_RETURN_IF_ERROR(contact_detector.Detect(p, max_gap, &net.contacts));
  if (const auto* walls = FindEffect<WallsEffectSpec>(scene)) {
    SEEP_ASSIGN_OR_RETURN(const std::vector<PlacedWall> placed,
                          PlaceWalls(*walls, p.x, p.y, p.radius));
    for (const PlacedWall& w : placed) {
      net.walls.push_back({w.wall.px, w.wall.py, w.wall.nx, w.wall.ny});
    }
    net.wall_contacts = FindWallContacts(p, net.walls, max_gap);
  }
  SEEP_ASSIGN_OR_RETURN(net, ConnectSceneNetwork(scene, std::move(net)));
  SEEP_RETURN_IF_ERROR(CheckRegionsHoldDomains(scene, net));
  return net;
}

void SetBoundaryPressures(const SceneSpec& scene, SceneNetwork* net) {
  FlowNetwork& flow = net->flow;
  const auto role = flow.role();
  auto pressure = flow.mutable_pressure();
  const auto set = [&](std::int32_t node, double value) {
    if (node < 0 || static_cast<std::size_t>(node) >= flow.num_domains()) return;
    if (role[static_cast<std::size_t>(node)] != DomainRole::kFixedPressure) return;
    pressure[static_cast<std::size_t>(node)] = value;
  };
  if (const auto& radial = scene.boundary.radial) {
    set(net->well_domain, radial->well_pressure_pa);  // only while it is a fixed-pressure well
    set(net->outer_node, radial->outer_pressure_pa);
  } else {
    set(net->inlet_node, scene.boundary.inlet_pressure_pa);
    set(net->outlet_node, scene.boundary.outlet_pressure_pa);
  }
  if (const auto* walls = FindEffect<WallsEffectSpec>(scene)) {
    for (std::size_t w = 0; w < net->wall_node.size() && w < walls->walls.size(); ++w) {
      if (const auto& drain = walls->walls[w].drain) set(net->wall_node[w], drain->pressure_pa);
    }
  }
}

Result<SceneNetwork> ConnectSceneNetwork(const SceneSpec& scene, SceneNetwork net) {
  net.domains = DomainNetwork{};
  net.flow = FlowNetwork{};
  net.pipe_contact.clear();
  net.reservoir_pipes.clear();
  net.inlet_node = net.outlet_node = net.well_domain = net.outer_node = -1;
  net.inlet_pipes = net.outlet_pipes = net.outer_pipes = 0;
  net.wall_node.clear();
  net.regions.clear();
  net.well_on_wall = false;
  const Packing& p = net.packing;
  const std::size_t n = p.size();
  const double max_gap = SceneContactGap(scene, net.mean_radius_m);
  DomainDetector domain_detector;
  if (net.walls.empty()) {
    SEEP_RETURN_IF_ERROR(domain_detector.Detect(p, net.contacts, {max_gap}, &net.domains));
  } else {
    const std::vector<DetectionWall> segments = ClipWalls(p, net.walls);
    const Status detected = domain_detector.Detect(p, net.contacts, segments, net.wall_contacts,
                                                   {max_gap}, &net.domains);
    if (!detected.ok()) {
      return Status(detected.code(), "scene.effects.walls: " + detected.message());
    }
  }
  const DomainNetwork& d = net.domains;
  const std::size_t num_domains = d.num_domains();
  if (num_domains == 0) {
    return FailedPrecondition(
        "scene.packing: the contact graph encloses no domain (no closed loop of touching "
        "particles); raise packing.contact_gap_m or use a denser packing");
  }
  if (scene.boundary.radial) {
    SEEP_RETURN_IF_ERROR(ConnectRadialBoundary(scene, net));
    return net;
  }
  if (scene.boundary.walls_only) {
    std::vector<double> gaps;
    FlowNetworkData data = DomainsAndInteriorPipes(scene, net, 0, gaps);
    AddDrainedWalls(scene, net, data, gaps);
    SEEP_RETURN_IF_ERROR(FillConductances(scene, gaps, data));
    SEEP_RETURN_IF_ERROR(CreateFlow(scene, std::move(data), net));
    return net;
  }

  // The sample's ends along the axis, from the particles' surfaces.
  const FlowAxis axis = scene.boundary.axis;
  double low = std::numeric_limits<double>::infinity();
  double high = -low;
  for (std::size_t i = 0; i < n; ++i) {
    low = std::min(low, AxisCoordinate(axis, p, i) - p.radius[i]);
    high = std::max(high, AxisCoordinate(axis, p, i) + p.radius[i]);
  }
  double domain_area = 0.0;
  for (double v : d.apparent_volume) domain_area += v;

  std::vector<double> gaps;
  FlowNetworkData data = DomainsAndInteriorPipes(scene, net, 2, gaps);
  net.inlet_node = static_cast<std::int32_t>(num_domains);
  net.outlet_node = static_cast<std::int32_t>(num_domains + 1);
  data.pressure[static_cast<std::size_t>(net.inlet_node)] = scene.boundary.inlet_pressure_pa;
  data.pressure[static_cast<std::size_t>(net.outlet_node)] = scene.boundary.outlet_pressure_pa;
  data.role[static_cast<std::size_t>(net.inlet_node)] = DomainRole::kFixedPressure;
  data.role[static_cast<std::size_t>(net.outlet_node)] = DomainRole::kFixedPressure;
  // Edge layer: particles whose extreme coordinate lies within one mean radius of the end.
  const double layer = net.mean_radius_m * (1.0 + 1e-9);
  for (std::size_t k = 0; k < d.num_boundary_pipes(); ++k) {
    if (d.outer_host_domain[static_cast<std::size_t>(d.boundary_pipe_outer_face[k])] >= 0) continue;
    if (OnWall(d, k)) continue;
    const auto c = static_cast<std::size_t>(d.boundary_pipe_contact[k]);
    const auto i = static_cast<std::size_t>(net.contacts.i[c]);
    const auto j = static_cast<std::size_t>(net.contacts.j[c]);
    const bool at_inlet = AxisCoordinate(axis, p, i) - p.radius[i] <= low + layer &&
                          AxisCoordinate(axis, p, j) - p.radius[j] <= low + layer;
    const bool at_outlet = AxisCoordinate(axis, p, i) + p.radius[i] >= high - layer &&
                           AxisCoordinate(axis, p, j) + p.radius[j] >= high - layer;
    if (at_inlet == at_outlet) continue;  // a side wall, or a sample one particle long
    if (at_inlet && scene.boundary.closed_inlet) continue;  // the low end is a no-flow base
    AddPipe(net, data, gaps, d.boundary_pipe_domain[k], at_inlet ? net.inlet_node : net.outlet_node,
            d.boundary_pipe_contact[k], d.boundary_pipe_length[k]);
    const auto host = static_cast<std::size_t>(d.boundary_pipe_domain[k]);
    const double face = axis == FlowAxis::kX ? d.boundary_pipe_x[k] : d.boundary_pipe_y[k];
    const double centroid = axis == FlowAxis::kX ? d.centroid_x[host] : d.centroid_y[host];
    net.reservoir_pipes.push_back(
        {data.pipe_length.size() - 1, at_inlet, face, 2.0 * face - centroid});
    ++(at_inlet ? net.inlet_pipes : net.outlet_pipes);
  }
  if ((net.inlet_pipes == 0 && !scene.boundary.closed_inlet) || net.outlet_pipes == 0) {
    return FailedPrecondition(fmt::format(
        "scene.boundary.axis: the sample has {} inlet and {} outlet pipes; both ends need hull "
        "contacts in their edge layer (is the packing connected from end to end?{})",
        net.inlet_pipes, net.outlet_pipes,
        net.walls.empty() ? ""
                          : " A wall across an end closes it: drain that wall, or leave "
                            "boundary.axis unset so that the walls bound the fluid"));
  }

  AddDrainedWalls(scene, net, data, gaps);
  SEEP_RETURN_IF_ERROR(FillConductances(scene, gaps, data));

  // Darcy geometry (see the header): conductance-weighted reservoir positions, plain-mean faces.
  double face_sum[2] = {0.0, 0.0};
  double reservoir_sum[2] = {0.0, 0.0};
  double weight_sum[2] = {0.0, 0.0};
  double count[2] = {0.0, 0.0};
  for (const ReservoirPipe& e : net.reservoir_pipes) {
    const int side = e.inlet ? 0 : 1;
    const double c = data.pipe_conductance[e.pipe];
    face_sum[side] += e.face_m;
    count[side] += 1.0;
    reservoir_sum[side] += c * e.image_m;
    weight_sum[side] += c;
  }
  if (scene.boundary.closed_inlet) {
    // One drained end: no through-flow, so no Darcy geometry.
    SEEP_RETURN_IF_ERROR(CreateFlow(scene, std::move(data), net));
    return net;
  }
  if (!(weight_sum[0] > 0.0) || !(weight_sum[1] > 0.0)) {
    return FailedPrecondition(
        "scene.boundary.axis: the pipes to the inlet or the outlet reservoir carry no flow (zero "
        "conductance)");
  }
  net.length_m = reservoir_sum[1] / weight_sum[1] - reservoir_sum[0] / weight_sum[0];
  const double face_span = face_sum[1] / count[1] - face_sum[0] / count[0];
  net.width_m = face_span > 0.0 ? domain_area / face_span : 0.0;
  SEEP_RETURN_IF_ERROR(CreateFlow(scene, std::move(data), net));
  return net;
}

}  // namespace seep::core
