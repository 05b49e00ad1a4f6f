#include "seep/core/network/fluid_weight.h"

#include <fmt/format.h>

#include <algorithm>

#include "seep/core/coupling/contact_point.h"
#include "seep/core/geometry/loop_polygon.h"

namespace seep::core {
namespace {

// Centroid of the polygon through the loop's centres, as the domain detection sums it.
void LoopCentroid(const ParticleView& p, std::span<const std::int32_t> loop, double* cx,
                  double* cy) {
  const auto first = static_cast<std::size_t>(loop[0]);
  LoopPolygonSums polygon(p.x[first], p.y[first]);
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const auto i = static_cast<std::size_t>(loop[k]);
    const auto j = static_cast<std::size_t>(loop[k + 1 < loop.size() ? k + 1 : 0]);
    polygon.AddEdge(p.x[i], p.y[i], p.x[j], p.y[j]);
  }
  *cx = polygon.centroid_x();
  *cy = polygon.centroid_y();
}

// The point of drained wall `node`'s wall nearest the centroid (cx, cy) of `pore`, with the wall
// where it is now: its line through one of the pore's vertices on it (their positions move with
// the wall), along the normal of the detection (walls translate, never turn).
Status DrainedWallPoint(const SceneNetwork& net, const ParticleView& positions, std::int32_t pore,
                        std::int32_t node, double cx, double cy, double* px, double* py) {
  const auto it = std::find(net.wall_node.begin(), net.wall_node.end(), node);
  if (it == net.wall_node.end()) {
    return Internal(fmt::format("network.fluid_weight: drained pipe to node {}, no wall's", node));
  }
  const auto w = static_cast<std::int32_t>(it - net.wall_node.begin());
  const DomainNetwork& d = net.domains;
  const auto begin = static_cast<std::size_t>(d.loop_offsets[static_cast<std::size_t>(pore)]);
  const auto end = static_cast<std::size_t>(d.loop_offsets[static_cast<std::size_t>(pore) + 1]);
  for (std::size_t k = begin; k < end; ++k) {
    const std::int32_t v = d.loop_particles[k];
    if (!d.walls.IsWallVertex(v)) continue;
    const auto slot = static_cast<std::size_t>(v - d.walls.num_particles);
    if (d.walls.vertex_wall[slot] != w && d.walls.vertex_other_wall[slot] != w) continue;
    const WallLine& line = net.walls[static_cast<std::size_t>(w)];
    const double vx = positions.x[static_cast<std::size_t>(v)];
    const double vy = positions.y[static_cast<std::size_t>(v)];
    const double distance = (cx - vx) * line.nx + (cy - vy) * line.ny;
    *px = cx - distance * line.nx;
    *py = cy - distance * line.ny;
    return Status::Ok();
  }
  return Internal(fmt::format(
      "network.fluid_weight: domain {} drains into wall {} but has no vertex on it", pore, w));
}

}  // namespace

std::optional<FluidWeight> SceneFluidWeight(const SceneSpec& scene) {
  if (!HasFluidWeight(scene)) return std::nullopt;
  const auto* gravity = FindEffect<GravityEffectSpec>(scene);
  const double rho = scene.fluid.density_kg_m3;
  return FluidWeight{rho * gravity->gx_m_s2, rho * gravity->gy_m_s2};
}

Status ComputeNodeWeightPressures(const SceneNetwork& net, const ParticleView& positions,
                                  const FluidWeight& weight, std::vector<double>* out) {
  const DomainNetwork& d = net.domains;
  const FlowNetwork& flow = net.flow;
  const std::size_t nodes = flow.num_domains();
  const std::size_t domains = d.num_domains();
  if (nodes < domains || net.pipe_contact.size() != flow.num_pipes()) {
    return Internal(fmt::format(
        "network.fluid_weight: {} flow nodes for {} domains, {} pipe contacts for {} pipes", nodes,
        domains, net.pipe_contact.size(), flow.num_pipes()));
  }
  out->assign(nodes, 0.0);
  std::vector<double> centroid_x(domains), centroid_y(domains);
  for (std::size_t k = 0; k < domains; ++k) {
    const auto begin = static_cast<std::size_t>(d.loop_offsets[k]);
    const auto end = static_cast<std::size_t>(d.loop_offsets[k + 1]);
    LoopCentroid(positions, std::span(d.loop_particles).subspan(begin, end - begin), &centroid_x[k],
                 &centroid_y[k]);
    (*out)[k] = weight.x * (centroid_x[k] - net.weight_origin_x_m) +
                weight.y * (centroid_y[k] - net.weight_origin_y_m);
  }
  if (nodes == domains) return Status::Ok();
  // Reservoirs: the mean contact point of their pipes; for a drained wall, the point of the
  // wall (where it is now) nearest the centroid of each pore it drains.
  std::vector<double> sum_x(nodes - domains, 0.0), sum_y(nodes - domains, 0.0);
  std::vector<double> count(nodes - domains, 0.0);
  const auto a = flow.pipe_domain_a();
  const auto b = flow.pipe_domain_b();
  for (std::size_t p = 0; p < flow.num_pipes(); ++p) {
    const std::int32_t contact = net.pipe_contact[p];
    if (contact >= 0 && d.walls.IsWallEdge(contact)) continue;  // joins two domains
    double px = 0.0, py = 0.0;
    if (contact < 0) {
      const bool a_is_domain = static_cast<std::size_t>(a[p]) < domains;
      const std::int32_t pore = a_is_domain ? a[p] : b[p];
      const std::int32_t node = a_is_domain ? b[p] : a[p];
      SEEP_RETURN_IF_ERROR(DrainedWallPoint(net, positions, pore, node,
                                            centroid_x[static_cast<std::size_t>(pore)],
                                            centroid_y[static_cast<std::size_t>(pore)], &px, &py));
    } else {
      const auto c = static_cast<std::size_t>(contact);
      const std::int32_t i = net.contacts.i[c];
      const std::int32_t j = net.contacts.j[c];
      const ContactArms arms = ComputeContactArms(positions, i, j);
      px = positions.x[static_cast<std::size_t>(i)] + arms.ax;
      py = positions.y[static_cast<std::size_t>(i)] + arms.ay;
    }
    for (const std::int32_t node : {a[p], b[p]}) {
      if (static_cast<std::size_t>(node) < domains) continue;
      const std::size_t r = static_cast<std::size_t>(node) - domains;
      sum_x[r] += px;
      sum_y[r] += py;
      count[r] += 1.0;
    }
  }
  for (std::size_t r = 0; r < count.size(); ++r) {
    if (count[r] == 0.0) continue;
    (*out)[domains + r] = weight.x * (sum_x[r] / count[r] - net.weight_origin_x_m) +
                          weight.y * (sum_y[r] / count[r] - net.weight_origin_y_m);
  }
  return Status::Ok();
}

std::vector<WallStretch> WettedWallStretches(const DomainNetwork& d) {
  std::vector<WallStretch> out;
  const DomainWalls& walls = d.walls;
  for (std::size_t domain = 0; domain < d.num_domains(); ++domain) {
    const auto begin = static_cast<std::size_t>(d.loop_offsets[domain]);
    const auto end = static_cast<std::size_t>(d.loop_offsets[domain + 1]);
    for (std::size_t k = begin; k < end; ++k) {
      const std::int32_t c = d.loop_contacts[k];
      if (!walls.IsWallEdge(c) || walls.edge_particle[walls.Edge(c)] >= 0) continue;
      out.push_back({d.loop_particles[k], d.loop_particles[k + 1 < end ? k + 1 : begin],
                     walls.edge_wall[walls.Edge(c)]});
    }
  }
  return out;
}

Status ApplyHeadOffsets(std::span<const double> node_weight, FlowNetwork* flow) {
  if (node_weight.size() != flow->num_domains()) {
    return Internal(fmt::format("network.fluid_weight: {} node weights for {} nodes",
                                node_weight.size(), flow->num_domains()));
  }
  const auto a = flow->pipe_domain_a();
  const auto b = flow->pipe_domain_b();
  std::vector<double> offset(flow->num_pipes());
  for (std::size_t p = 0; p < offset.size(); ++p) {
    offset[p] =
        node_weight[static_cast<std::size_t>(b[p])] - node_weight[static_cast<std::size_t>(a[p])];
  }
  return flow->SetPipeHeadOffsets(offset);
}

void ApplyHydrostaticStart(const SceneSpec& scene, const FluidWeight& weight,
                           std::span<const double> node_weight, SceneNetwork* net) {
  const BoundarySpec& b = scene.boundary;
  const double reference = weight.x * (b.initial_pressure_x_m - net->weight_origin_x_m) +
                           weight.y * (b.initial_pressure_y_m - net->weight_origin_y_m);
  FlowNetwork* flow = &net->flow;
  const auto role = flow->role();
  const auto pressure = flow->mutable_pressure();
  for (std::size_t n = 0; n < pressure.size(); ++n) {
    if (role[n] == DomainRole::kFixedPressure) continue;
    pressure[n] = b.initial_pressure_pa + (node_weight[n] - reference);
  }
}

}  // namespace seep::core
