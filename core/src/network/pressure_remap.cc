#include "seep/core/network/pressure_remap.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>
#include <utility>

#include "seep/core/flow/storage_volume.h"

namespace seep::core {
namespace {

// Loop vertices numbered alike in two detections of the same particles: a particle keeps its id;
// a wall vertex, whose id depends on what else touches the walls, is numbered after the particles
// by what it is, (wall, particle, -1) for a foot and (wall, -1, other wall) for a corner
// (domain_walls.h), so that the same vertex gets the same number in both.
class SharedVertexIds {
 public:
  SharedVertexIds(const DomainNetwork& a, const DomainNetwork& b) {
    std::int32_t particles = 0;  // one past the largest particle id in either network's loops
    for (const DomainNetwork* d : {&a, &b}) {
      for (const auto* loops : {&d->loop_particles, &d->outer_particles}) {
        for (const std::int32_t id : *loops) {
          if (!d->walls.IsWallVertex(id)) particles = std::max(particles, id + 1);
        }
      }
    }
    std::vector<WallVertex> all;
    for (const DomainNetwork* d : {&a, &b}) {
      for (std::size_t v = 0; v < d->walls.num_vertices(); ++v) all.push_back(WallVertexOf(*d, v));
    }
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    const auto number = [&](const DomainNetwork& d, std::vector<std::uint32_t>* out) {
      out->resize(d.walls.num_vertices());
      for (std::size_t v = 0; v < out->size(); ++v) {
        const auto at = std::lower_bound(all.begin(), all.end(), WallVertexOf(d, v));
        (*out)[v] =
            static_cast<std::uint32_t>(particles) + static_cast<std::uint32_t>(at - all.begin());
      }
    };
    number(a, &wall_ids_[0]);
    number(b, &wall_ids_[1]);
    walls_[0] = &a.walls;
    walls_[1] = &b.walls;
    count_ = static_cast<std::size_t>(particles) + all.size();
  }

  std::size_t count() const { return count_; }
  // The shared number of loop id `id` of network `which` (0: a, 1: b).
  std::uint32_t Of(int which, std::int32_t id) const {
    const DomainWalls& walls = *walls_[which];
    if (!walls.IsWallVertex(id)) return static_cast<std::uint32_t>(id);
    return wall_ids_[which][static_cast<std::size_t>(id - walls.num_particles)];
  }

 private:
  using WallVertex = std::tuple<std::int32_t, std::int32_t, std::int32_t>;
  static WallVertex WallVertexOf(const DomainNetwork& d, std::size_t v) {
    return {d.walls.vertex_wall[v], d.walls.vertex_particle[v], d.walls.vertex_other_wall[v]};
  }

  const DomainWalls* walls_[2] = {nullptr, nullptr};
  std::vector<std::uint32_t> wall_ids_[2];
  std::size_t count_ = 0;
};

// Every half-edge of a network's loops (domain loops CCW, outer loops clockwise), grouped by its
// origin vertex (shared numbering) in loop order: domains first, then outer loops. Its face is
// the domain on its left: the domain itself, an island's host, or kOutside for a top-level outer
// loop, which borders the outside. Where a directed half-edge appears more than once, the first
// with a domain on its left is the one that counts (LeftFace), as in a map filled in loop order.
class HalfEdges {
 public:
  static constexpr std::int32_t kOutside = -1;
  static constexpr std::int32_t kNone = -2;

  HalfEdges(const DomainNetwork& d, const SharedVertexIds& ids, int which) {
    first_.assign(ids.count() + 1, 0);
    const auto walk = [&](const std::vector<std::int32_t>& loops,
                          const std::vector<std::int32_t>& offsets, auto&& face_of, auto&& visit) {
      for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
        const auto begin = static_cast<std::size_t>(offsets[f]);
        const auto end = static_cast<std::size_t>(offsets[f + 1]);
        const std::int32_t face = face_of(f);
        for (std::size_t k = begin; k < end; ++k) {
          const std::int32_t next = loops[k + 1 < end ? k + 1 : begin];
          visit(ids.Of(which, loops[k]), ids.Of(which, next), face);
        }
      }
    };
    const auto domain = [](std::size_t f) { return static_cast<std::int32_t>(f); };
    const auto host = [&d](std::size_t f) {
      const std::int32_t h = d.outer_host_domain[f];
      return h < 0 ? kOutside : h;
    };
    const auto both = [&](auto&& visit) {
      walk(d.loop_particles, d.loop_offsets, domain, visit);
      walk(d.outer_particles, d.outer_offsets, host, visit);
    };
    both([&](std::uint32_t from, std::uint32_t, std::int32_t) { ++first_[from + 1]; });
    for (std::size_t v = 1; v < first_.size(); ++v) first_[v] += first_[v - 1];
    target_.resize(first_.back());
    face_.resize(first_.back());
    std::vector<std::uint32_t> fill(first_.begin(), first_.end() - 1);
    both([&](std::uint32_t from, std::uint32_t to, std::int32_t face) {
      const std::uint32_t at = fill[from]++;
      target_[at] = to;
      face_[at] = face;
    });
  }

  // The domain on the left of from -> to, or kNone.
  std::int32_t LeftFace(std::uint32_t from, std::uint32_t to) const {
    for (std::uint32_t k = first_[from]; k < first_[from + 1]; ++k) {
      if (target_[k] == to && face_[k] >= 0) return face_[k];
    }
    return kNone;
  }
  // Whether some loop walks from -> to or to -> from.
  bool HasEdge(std::uint32_t from, std::uint32_t to) const {
    return Walks(from, to) || Walks(to, from);
  }
  // Calls visit(from, to, face) once per directed half-edge with a domain on its left, with the
  // face LeftFace gives.
  template <typename Visit>
  void ForEachLeft(Visit&& visit) const {
    for (std::uint32_t from = 0; from + 1 < first_.size(); ++from) {
      for (std::uint32_t k = first_[from]; k < first_[from + 1]; ++k) {
        if (face_[k] >= 0 && FirstWithLeft(from, k)) visit(from, target_[k], face_[k]);
      }
    }
  }

 private:
  bool Walks(std::uint32_t from, std::uint32_t to) const {
    for (std::uint32_t k = first_[from]; k < first_[from + 1]; ++k) {
      if (target_[k] == to) return true;
    }
    return false;
  }
  // Entry k is the first of its origin's entries to its target with a domain on the left.
  bool FirstWithLeft(std::uint32_t from, std::uint32_t k) const {
    for (std::uint32_t e = first_[from]; e < k; ++e) {
      if (target_[e] == target_[k] && face_[e] >= 0) return false;
    }
    return true;
  }

  std::vector<std::uint32_t> first_;  // per shared vertex: its first entry (CSR offsets)
  std::vector<std::uint32_t> target_;
  std::vector<std::int32_t> face_;
};

// What the matching indexes by: CSR loops, ids that are particles (>= 0) or wall vertices of the
// network's own walls, and island hosts among its domains. `which` names the network ("old" or
// "new") in the message.
Status CheckLoops(const DomainNetwork& d, const char* which) {
  const auto loops = [&](const std::vector<std::int32_t>& offsets,
                         const std::vector<std::int32_t>& ids, const char* field) -> Status {
    for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
      if (offsets[f] < 0 || offsets[f] > offsets[f + 1]) {
        return InvalidArgument(
            fmt::format("remap.{}_network.{}: offsets are not ascending at {}", which, field, f));
      }
    }
    if (offsets.empty() || static_cast<std::size_t>(offsets.back()) != ids.size()) {
      return InvalidArgument(fmt::format("remap.{}_network.{}: offsets do not end at its {} ids",
                                         which, field, ids.size()));
    }
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const std::int32_t id = ids[k];
      const bool wall = d.walls.IsWallVertex(id);
      if (id < 0 || (wall && static_cast<std::size_t>(id - d.walls.num_particles) >=
                                 d.walls.num_vertices())) {
        return InvalidArgument(fmt::format(
            "remap.{}_network.{}[{}]: {} is neither a particle nor one of the {} wall vertices",
            which, field, k, id, d.walls.num_vertices()));
      }
    }
    return Status::Ok();
  };
  SEEP_RETURN_IF_ERROR(loops(d.loop_offsets, d.loop_particles, "loop_particles"));
  SEEP_RETURN_IF_ERROR(loops(d.outer_offsets, d.outer_particles, "outer_particles"));
  if (d.outer_host_domain.size() + 1 != d.outer_offsets.size()) {
    return InvalidArgument(
        fmt::format("remap.{}_network.outer_host_domain: {} hosts for {} islands", which,
                    d.outer_host_domain.size(), d.outer_offsets.size() - 1));
  }
  for (std::size_t o = 0; o < d.outer_host_domain.size(); ++o) {
    if (d.outer_host_domain[o] >= static_cast<std::int32_t>(d.num_domains())) {
      return InvalidArgument(fmt::format("remap.{}_network.outer_host_domain[{}]: domain {} of {}",
                                         which, o, d.outer_host_domain[o], d.num_domains()));
    }
  }
  if (d.loop_offsets.size() != d.num_domains() + 1) {
    return InvalidArgument(fmt::format("remap.{}_network.loop_offsets: {} entries for {} domains",
                                       which, d.loop_offsets.size(), d.num_domains()));
  }
  return Status::Ok();
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
  SEEP_RETURN_IF_ERROR(CheckLoops(old_network, "old"));
  SEEP_RETURN_IF_ERROR(CheckLoops(new_network, "new"));
  // Union-find over old domains [0, n_old) and new domains [n_old, n_old + n_new).
  std::vector<std::int32_t> parent(n_old + n_new);
  std::iota(parent.begin(), parent.end(), 0);
  const SharedVertexIds ids(old_network, new_network);
  const HalfEdges old_edges(old_network, ids, 0);
  const HalfEdges new_edges(new_network, ids, 1);
  const auto join = [&parent](std::int32_t x, std::int32_t y) {
    const std::int32_t a = Find(parent, x);
    const std::int32_t b = Find(parent, y);
    // The smaller root wins: every root is its set's smallest member, whatever the order of the
    // unions.
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  };
  old_edges.ForEachLeft([&](std::uint32_t from, std::uint32_t to, std::int32_t face) {
    // A half-edge in both networks: the old and the new domain on its left overlap.
    const std::int32_t now = new_edges.LeftFace(from, to);
    if (now >= 0) join(face, static_cast<std::int32_t>(n_old) + now);
    // A loop contact of the old network that bounds no loop of the new one (lost, or left
    // dangling) joins the two old faces beside it: they are one face now. This also catches a
    // domain whose every loop contact broke at once, which no surviving half-edge would match.
    // (Without a domain on the twin's left, the outside was beside it: that face opened.)
    if (new_edges.HasEdge(from, to)) return;
    const std::int32_t twin = old_edges.LeftFace(to, from);
    if (twin >= 0) join(face, twin);
  });

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
