// CollectSceneFields: a Simulation's state as plain arrays, with the analytic pressure where the
// scene has one (see scene_fields.h).
#include "seep/core/run/scene_fields.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include "seep/core/flow/pipe_head.h"
#include "seep/core/network/scene_walls.h"
#include "seep/core/reference/analytic_solutions.h"

namespace seep::core {
namespace {

// The one place particle positions are read: a rigid scene's packing never moves; when coupled
// scenes move their particles, this is where the current positions are to come from.
// The particles as they are now: a moving scene's DEM positions (the network's packing holds the
// positions of its last detection, which the domain centroids still follow).
Packing CurrentPacking(const Simulation& sim) {
  const ParticleView view = sim.particles();
  Packing packing;
  packing.x.assign(view.x.begin(), view.x.end());
  packing.y.assign(view.y.begin(), view.y.end());
  packing.radius.assign(view.radius.begin(), view.radius.end());
  return packing;
}

double Axis(FlowAxis axis, double x, double y) { return axis == FlowAxis::kX ? x : y; }

// The contact point of contact c: on the line of centres, halfway across the gap (or overlap).
void ContactPoint(const Packing& p, const ContactList& contacts, std::size_t c, double* x,
                  double* y) {
  const auto i = static_cast<std::size_t>(contacts.i[c]);
  const auto j = static_cast<std::size_t>(contacts.j[c]);
  const double dx = p.x[j] - p.x[i];
  const double dy = p.y[j] - p.y[i];
  const double dist = std::hypot(dx, dy);
  const double along = dist > 0.0 ? (p.radius[i] + 0.5 * contacts.gap[c]) / dist : 0.5;
  *x = p.x[i] + along * dx;
  *y = p.y[i] + along * dy;
}

// The inlet reservoir's effective position along the axis: the conductance-weighted mean of the
// centroid images of its pipes, as BuildSceneNetwork places it (scene_network.h).
double InletPosition(const SceneNetwork& net) {
  double sum = 0.0;
  double weight = 0.0;
  for (const ReservoirPipe& e : net.reservoir_pipes) {
    if (!e.inlet) continue;
    const double c = net.flow.pipe_conductance()[e.pipe];
    sum += c * e.image_m;
    weight += c;
  }
  return weight > 0.0 ? sum / weight : 0.0;
}

// k / mu along the axis: the affine estimate over every pipe, a reservoir pipe spanning its
// domain's centroid and that centroid's image through the contact, over the Darcy box.
double AxisMobility(const SceneNetwork& net, FlowAxis axis) {
  const DomainNetwork& d = net.domains;
  const std::vector<double>& centroid = axis == FlowAxis::kX ? d.centroid_x : d.centroid_y;
  const std::size_t domains = d.num_domains();
  std::vector<double> image(net.flow.num_pipes(), 0.0);
  std::vector<std::uint8_t> is_reservoir(net.flow.num_pipes(), 0);
  for (const ReservoirPipe& e : net.reservoir_pipes) {
    image[e.pipe] = e.image_m;
    is_reservoir[e.pipe] = 1;
  }
  double sum = 0.0;
  for (std::size_t p = 0; p < net.flow.num_pipes(); ++p) {
    const auto a = static_cast<std::size_t>(net.flow.pipe_domain_a()[p]);
    const auto b = static_cast<std::size_t>(net.flow.pipe_domain_b()[p]);
    double span = 0.0;
    if (is_reservoir[p] != 0) {
      span = image[p] - centroid[a];
    } else if (a < domains && b < domains) {
      span = centroid[b] - centroid[a];
    }
    sum += net.flow.pipe_conductance()[p] * span * span;
  }
  const double box = net.length_m * net.width_m;
  return box > 0.0 ? sum / box : 0.0;
}

void AddLinearAnalytic(const Simulation& sim, SceneFields* f) {
  const SceneSpec& scene = sim.scene();
  const SceneNetwork& net = sim.network();
  const FlowAxis axis = scene.boundary.axis;
  const double length = net.length_m;
  if (!(length > 0.0)) return;
  const double inlet = InletPosition(net);
  const double p_in = scene.boundary.inlet_pressure_pa;
  const double p_out = scene.boundary.outlet_pressure_pa;
  const double p_0 = scene.boundary.initial_pressure_pa;
  const bool steady = scene.solver.kind == SolverKind::kSteady;
  double T = 0.0;
  if (!steady) {
    double stored = 0.0;
    double apparent = 0.0;
    const auto pore_volume = net.flow.pore_volume();
    const auto apparent_volume = net.flow.apparent_volume();
    for (std::size_t d = 0; d < net.domains.num_domains(); ++d) {
      stored +=
          scene.solver.storage_factor *
          (scene.solver.storage == StorageVolume::kPore ? pore_volume[d] : apparent_volume[d]);
      apparent += apparent_volume[d];
    }
    if (!(stored > 0.0) || !(apparent > 0.0)) return;
    const double n_s = stored / apparent;
    const double c = AxisMobility(net, axis) * scene.fluid.bulk_modulus_pa / n_s;
    T = c * sim.time_s() / (length * length);
  }
  // Built as std::string and moved in: assigning a literal trips GCC 12's -Wrestrict false
  // positive at -O3.
  f->analytic_kind = std::string(steady ? "linear_steady" : "linear_transient");
  f->axis_name = std::string(axis == FlowAxis::kX ? "x" : "y");
  f->axis_length = length;
  const std::size_t n = f->domain_centroid_x.size();
  f->domain_axis_coordinate.resize(n);
  f->domain_analytic_pressure.resize(n);
  for (std::size_t d = 0; d < n; ++d) {
    const double s = Axis(axis, f->domain_centroid_x[d], f->domain_centroid_y[d]) - inlet;
    const double xi = s / length;
    f->domain_axis_coordinate[d] = s;
    f->domain_analytic_pressure[d] =
        steady ? p_in + (p_out - p_in) * xi
               : p_0 + (p_in - p_0) * DiffusionDirichletDirichlet(xi, T) +
                     (p_out - p_0) * DiffusionDirichletDirichlet(1.0 - xi, T);
  }
}

void AddRadialAnalytic(const Simulation& sim, SceneFields* f) {
  const RadialBoundarySpec& radial = *sim.scene().boundary.radial;
  const SceneNetwork& net = sim.network();
  const double r_e = net.outer_reservoir_radius_m;
  if (sim.scene().solver.kind != SolverKind::kSteady || !(r_e > radial.well_radius_m)) return;
  f->analytic_kind = std::string("radial_steady");
  f->axis_name = std::string("r");
  f->axis_length = r_e;
  const std::size_t n = f->domain_centroid_x.size();
  f->domain_axis_coordinate.resize(n);
  f->domain_analytic_pressure.resize(n);
  for (std::size_t d = 0; d < n; ++d) {
    const double r =
        std::hypot(f->domain_centroid_x[d] - net.well_x_m, f->domain_centroid_y[d] - net.well_y_m);
    f->domain_axis_coordinate[d] = r;
    f->domain_analytic_pressure[d] =
        static_cast<std::int32_t>(d) == net.well_domain
            ? radial.well_pressure_pa
            : ThiemPressure(std::max(r, radial.well_radius_m), radial.well_radius_m, r_e,
                            radial.well_pressure_pa, radial.outer_pressure_pa);
  }
}

}  // namespace

SceneFields CollectSceneFields(const Simulation& sim) {
  const SceneNetwork& net = sim.network();
  const Packing packing = CurrentPacking(sim);
  const DomainNetwork& d = net.domains;
  const FlowNetwork& flow = net.flow;
  SceneFields f;
  f.step = sim.step();
  f.time_s = sim.time_s();
  f.particle_x = packing.x;
  f.particle_y = packing.y;
  f.particle_radius = packing.radius;

  const std::size_t domains = d.num_domains();
  f.domain_centroid_x = d.centroid_x;
  f.domain_centroid_y = d.centroid_y;
  f.domain_pressure.assign(flow.pressure().begin(), flow.pressure().begin() + domains);
  f.domain_apparent_volume.assign(flow.apparent_volume().begin(),
                                  flow.apparent_volume().begin() + domains);
  const std::vector<double> pore = sim.PoreVolumes();
  f.domain_pore_volume.assign(pore.begin(), pore.begin() + static_cast<std::ptrdiff_t>(domains));
  f.domain_loop_offsets = d.loop_offsets;
  f.domain_loop_particles = d.loop_particles;
  if (!d.walls.empty()) {
    f.wall_vertex_x.resize(d.walls.num_vertices());
    f.wall_vertex_y.resize(d.walls.num_vertices());
    const std::vector<WallLine> lines =
        sim.stepper().state().walls.empty() ? net.walls : WallLines(sim.stepper().state().walls);
    WallVertexPositions(d.walls, packing.x, packing.y, lines, f.wall_vertex_x, f.wall_vertex_y);
  }

  const std::size_t pipes = flow.num_pipes();
  f.pipe_domain_a.resize(pipes);
  f.pipe_domain_b.resize(pipes);
  f.pipe_particle_i.resize(pipes);
  f.pipe_particle_j.resize(pipes);
  f.pipe_x0.resize(pipes);
  f.pipe_y0.resize(pipes);
  f.pipe_x1.resize(pipes);
  f.pipe_y1.resize(pipes);
  f.pipe_aperture.assign(flow.pipe_aperture().begin(), flow.pipe_aperture().end());
  f.pipe_conductance.assign(flow.pipe_conductance().begin(), flow.pipe_conductance().end());
  f.pipe_flow.resize(pipes);
  for (std::size_t p = 0; p < pipes; ++p) {
    const std::int32_t a = flow.pipe_domain_a()[p];
    const std::int32_t b = flow.pipe_domain_b()[p];
    const auto ua = static_cast<std::size_t>(a);
    const auto ub = static_cast<std::size_t>(b);
    f.pipe_flow[p] = PipeInflowToA(flow, p);  // the head included when the fluid has weight
    const std::int32_t contact = net.pipe_contact[p];
    const auto c = static_cast<std::size_t>(contact);
    const bool through_wall = contact < 0;
    const bool on_wall = !through_wall && d.walls.IsWallEdge(contact);
    if (through_wall) {
      const auto wall = std::find(net.wall_node.begin(), net.wall_node.end(), b);
      f.pipe_particle_i[p] = -1;
      f.pipe_particle_j[p] = -1 - static_cast<std::int32_t>(wall - net.wall_node.begin());
    } else if (on_wall) {
      const std::size_t e = d.walls.Edge(contact);
      f.pipe_particle_i[p] = d.walls.edge_particle[e];
      f.pipe_particle_j[p] = -1 - d.walls.edge_wall[e];
    } else {
      f.pipe_particle_i[p] = net.contacts.i[c];
      f.pipe_particle_j[p] = net.contacts.j[c];
    }
    // A reservoir node is past the domains; the flow network puts the interior domain first.
    const bool to_reservoir = ub >= domains;
    f.pipe_domain_a[p] = a;
    f.pipe_domain_b[p] = to_reservoir ? -1 : b;
    f.pipe_x0[p] = ua < domains ? d.centroid_x[ua] : 0.0;
    f.pipe_y0[p] = ua < domains ? d.centroid_y[ua] : 0.0;
    if (through_wall) {
      // The foot of domain a's centroid on the drained wall.
      const auto w = static_cast<std::size_t>(-1 - f.pipe_particle_j[p]);
      const WallLine& line = net.walls[w];
      const double h = (f.pipe_x0[p] - line.px) * line.nx + (f.pipe_y0[p] - line.py) * line.ny;
      f.pipe_x1[p] = f.pipe_x0[p] - h * line.nx;
      f.pipe_y1[p] = f.pipe_y0[p] - h * line.ny;
    } else if (to_reservoir) {
      ContactPoint(packing, net.contacts, c, &f.pipe_x1[p], &f.pipe_y1[p]);
    } else {
      f.pipe_x1[p] = d.centroid_x[ub];
      f.pipe_y1[p] = d.centroid_y[ub];
    }
  }

  if (HasMechanics(sim.scene())) {
    // Moving particles: no closed-form pressure field to compare with.
  } else if (sim.scene().boundary.radial.has_value()) {
    AddRadialAnalytic(sim, &f);
  } else {
    AddLinearAnalytic(sim, &f);
  }
  return f;
}

}  // namespace seep::core
