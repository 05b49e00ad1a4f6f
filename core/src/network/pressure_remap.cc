#include "seep/core/network/pressure_remap.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <tuple>
#include <utility>

#include "seep/core/flow/storage_volume.h"

namespace seep::core {
namespace {

// A loop vertex by what it is, not by its id, so that two detections agree: a particle is
// (-1, particle, -1); a wall vertex, whose id depends on what else touches the walls, is
// (wall, particle, -1) for a foot and (wall, -1, other wall) for a corner (domain_walls.h).
using Vertex = std::tuple<std::int32_t, std::int32_t, std::int32_t>;
using HalfEdge = std::pair<Vertex, Vertex>;

Vertex VertexOf(const DomainNetwork& d, std::int32_t id) {
  const DomainWalls& walls = d.walls;
  if (!walls.IsWallVertex(id)) return {-1, id, -1};
  const auto v = static_cast<std::size_t>(id - walls.num_particles);
  return {walls.vertex_wall[v], walls.vertex_particle[v], walls.vertex_other_wall[v]};
}

std::pair<Vertex, Vertex> Unordered(const Vertex& a, const Vertex& b) { return std::minmax(a, b); }

// Half-edge -> the domain on its left: every domain loop (CCW), and the outer loops of islands
// (clockwise, host domain on the left). Top-level outer loops border the outside: left out.
std::map<HalfEdge, std::int32_t> LeftFaces(const DomainNetwork& d) {
  std::map<HalfEdge, std::int32_t> left;
  auto add_loop = [&left, &d](const std::vector<std::int32_t>& particles, std::size_t begin,
                              std::size_t end, std::int32_t face) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::int32_t next = particles[k + 1 < end ? k + 1 : begin];
      left.emplace(HalfEdge{VertexOf(d, particles[k]), VertexOf(d, next)}, face);
    }
  };
  for (std::size_t dom = 0; dom < d.num_domains(); ++dom) {
    add_loop(d.loop_particles, static_cast<std::size_t>(d.loop_offsets[dom]),
             static_cast<std::size_t>(d.loop_offsets[dom + 1]), static_cast<std::int32_t>(dom));
  }
  for (std::size_t o = 0; o < d.num_outer_faces(); ++o) {
    if (d.outer_host_domain[o] < 0) continue;
    add_loop(d.outer_particles, static_cast<std::size_t>(d.outer_offsets[o]),
             static_cast<std::size_t>(d.outer_offsets[o + 1]), d.outer_host_domain[o]);
  }
  return left;
}

std::int32_t Find(std::vector<std::int32_t>& parent, std::int32_t x) {
  while (parent[static_cast<std::size_t>(x)] != x) {
    auto& p = parent[static_cast<std::size_t>(x)];
    p = parent[static_cast<std::size_t>(p)];
    x = p;
  }
  return x;
}

// The storage volume per domain: `pore` or `apparent` as the model says, times its factor.
double StorageOf(std::span<const double> pore, std::span<const double> apparent, std::size_t dom,
                 const StorageModel& storage) {
  const double v = storage.volume == StorageVolume::kPore ? pore[dom] : apparent[dom];
  return StorageVolumeFrom(v, storage.factor, storage.floor_m2);
}

}  // namespace

void PocketPressures(const FlowNetwork& flow, std::span<const std::int32_t> pockets,
                     std::span<double> pressure) {
  if (pockets.empty()) return;
  const std::size_t n = flow.num_domains();
  std::vector<std::int32_t> slot(n, -1);  // node -> its index in pockets, or -1
  for (std::size_t k = 0; k < pockets.size(); ++k) {
    slot[static_cast<std::size_t>(pockets[k])] = static_cast<std::int32_t>(k);
  }
  // Per pocket: sum C and sum C P over its pipes to fixed nodes, and to other neighbours.
  struct Sums {
    double fixed_c = 0.0, fixed_cp = 0.0, free_c = 0.0, free_cp = 0.0;
  };
  std::vector<Sums> sums(pockets.size());
  const auto a = flow.pipe_domain_a();
  const auto b = flow.pipe_domain_b();
  const auto c = flow.pipe_conductance();
  const auto role = flow.role();
  const auto add = [&](std::int32_t pocket, std::int32_t other, double conductance) {
    const std::int32_t k = slot[static_cast<std::size_t>(pocket)];
    if (k < 0 || slot[static_cast<std::size_t>(other)] >= 0) return;  // not a pocket, or two
    Sums& s = sums[static_cast<std::size_t>(k)];
    const double p = pressure[static_cast<std::size_t>(other)];
    if (role[static_cast<std::size_t>(other)] == DomainRole::kFixedPressure) {
      s.fixed_c += conductance;
      s.fixed_cp += conductance * p;
    } else {
      s.free_c += conductance;
      s.free_cp += conductance * p;
    }
  };
  for (std::size_t p = 0; p < c.size(); ++p) {
    add(a[p], b[p], c[p]);
    add(b[p], a[p], c[p]);
  }
  for (std::size_t k = 0; k < pockets.size(); ++k) {
    // A pocket that is a boundary node (a pressure region took it) holds the boundary's value.
    if (role[static_cast<std::size_t>(pockets[k])] == DomainRole::kFixedPressure) continue;
    const Sums& s = sums[k];
    double& p = pressure[static_cast<std::size_t>(pockets[k])];
    if (s.fixed_c > 0.0) {
      p = s.fixed_cp / s.fixed_c;
    } else if (s.free_c > 0.0) {
      p = s.free_cp / s.free_c;
    }
  }
}

Result<PressureRemapReport> RemapPressures(const DomainNetwork& old_network,
                                           std::span<const double> old_pressure,
                                           const DomainNetwork& new_network,
                                           const PressureRemapOptions& options,
                                           std::vector<double>* new_pressure) {
  SEEP_RETURN_IF_ERROR(ValidateStorageModel(options.storage));
  const std::size_t n_old = old_network.num_domains();
  const std::size_t n_new = new_network.num_domains();
  if (old_pressure.size() < n_old) {
    return InvalidArgument(fmt::format("remap.old_pressure: {} values for {} old domains",
                                       old_pressure.size(), n_old));
  }
  const std::span<const double> old_pore =
      options.old_pore_volume.empty() ? old_network.pore_volume : options.old_pore_volume;
  const std::span<const double> old_apparent = options.old_apparent_volume.empty()
                                                   ? old_network.apparent_volume
                                                   : options.old_apparent_volume;
  if (old_pore.size() < n_old || old_apparent.size() < n_old) {
    return InvalidArgument(fmt::format("remap.old_volume: {} / {} values for {} old domains",
                                       old_pore.size(), old_apparent.size(), n_old));
  }
  if (!std::isfinite(options.unmatched_pressure)) {
    return InvalidArgument(fmt::format("remap.unmatched_pressure: must be finite (got {})",
                                       options.unmatched_pressure));
  }
  // Union-find over old domains [0, n_old) and new domains [n_old, n_old + n_new).
  std::vector<std::int32_t> parent(n_old + n_new);
  std::iota(parent.begin(), parent.end(), 0);
  const auto old_left = LeftFaces(old_network);
  const auto new_left = LeftFaces(new_network);
  // Both maps are sorted by half-edge: walk them together.
  auto o = old_left.begin();
  auto n = new_left.begin();
  while (o != old_left.end() && n != new_left.end()) {
    if (o->first < n->first) {
      ++o;
    } else if (n->first < o->first) {
      ++n;
    } else {
      const std::int32_t a = Find(parent, o->second);
      const std::int32_t b = Find(parent, static_cast<std::int32_t>(n_old) + n->second);
      // The smaller root wins: the result does not depend on the order of the unions.
      if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
      ++o;
      ++n;
    }
  }
  // A loop contact of the old network that bounds no loop of the new one (lost, or left dangling)
  // joins the two old faces beside it: they are one face now. This also catches a domain whose
  // every loop contact broke at once, which no surviving half-edge would match.
  std::set<HalfEdge> new_edges;  // unordered: (smaller vertex, larger vertex)
  const auto add_edges = [&new_edges, &new_network](const std::vector<std::int32_t>& particles,
                                                    const std::vector<std::int32_t>& offsets) {
    for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
      const auto begin = static_cast<std::size_t>(offsets[f]);
      const auto end = static_cast<std::size_t>(offsets[f + 1]);
      for (std::size_t k = begin; k < end; ++k) {
        const std::int32_t next = particles[k + 1 < end ? k + 1 : begin];
        new_edges.insert(
            Unordered(VertexOf(new_network, particles[k]), VertexOf(new_network, next)));
      }
    }
  };
  add_edges(new_network.loop_particles, new_network.loop_offsets);
  add_edges(new_network.outer_particles, new_network.outer_offsets);
  for (const auto& [edge, face] : old_left) {
    if (new_edges.count(Unordered(edge.first, edge.second)) != 0) continue;
    const auto twin = old_left.find(HalfEdge{edge.second, edge.first});
    if (twin == old_left.end()) continue;  // the outside was beside it: that face opened
    const std::int32_t a = Find(parent, face);
    const std::int32_t b = Find(parent, twin->second);
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }

  PressureRemapReport report;
  std::vector<double> stored(n_old + n_new, 0.0);  // per root: sum V_s P of old members
  std::vector<double> volume(n_old + n_new, 0.0);  // per root: sum V_s of old members
  std::vector<std::uint8_t> has_new(n_old + n_new, 0);
  std::vector<std::int32_t> old_members(n_old + n_new, 0);
  std::vector<double> plain_sum(n_old + n_new, 0.0);  // per root: sum P of old members
  for (std::size_t k = 0; k < n_new; ++k) {
    has_new[static_cast<std::size_t>(Find(parent, static_cast<std::int32_t>(n_old + k)))] = 1;
  }
  for (std::size_t k = 0; k < n_old; ++k) {
    const auto root = static_cast<std::size_t>(Find(parent, static_cast<std::int32_t>(k)));
    const double v = StorageOf(old_pore, old_apparent, k, options.storage);
    report.old_stored += v * old_pressure[k];
    stored[root] += v * old_pressure[k];
    volume[root] += v;
    ++old_members[root];
    plain_sum[root] += old_pressure[k];
    if (has_new[root] == 0) ++report.unmatched_old;
    if (root == k && has_new[root] != 0) ++report.clusters;
  }
  new_pressure->assign(n_new, options.unmatched_pressure);
  for (std::size_t k = 0; k < n_new; ++k) {
    const auto root = static_cast<std::size_t>(Find(parent, static_cast<std::int32_t>(n_old + k)));
    if (root < n_old && old_members[root] == 1) {
      (*new_pressure)[k] = old_pressure[root];  // unchanged or split: copied exactly
    } else if (root < n_old && volume[root] > 0.0) {
      (*new_pressure)[k] = stored[root] / volume[root];
    } else if (root < n_old) {
      // Old domains of zero storage: their plain mean.
      (*new_pressure)[k] = plain_sum[root] / old_members[root];
    } else {
      ++report.unmatched_new;
      report.unmatched_new_domains.push_back(static_cast<std::int32_t>(k));
    }
    report.new_stored +=
        StorageOf(new_network.pore_volume, new_network.apparent_volume, k, options.storage) *
        (*new_pressure)[k];
  }
  return report;
}

}  // namespace seep::core
