// Face tracing of the planar contact graph (see domain_detection.h for the algorithm and the
// conventions). Everything lives in flat arrays owned by the detector and reused across calls;
// the hot path has no per-domain allocation.
#include "seep/core/geometry/domain_detection.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <string>

#include "../sizes.h"
#include "contact_pipe.h"
#include "seep/core/geometry/disk_overlap.h"
#include "seep/core/geometry/loop_polygon.h"

namespace seep::core {
namespace {}  // namespace

void DomainNetwork::Clear() {
  loop_offsets.assign(1, 0);
  loop_particles.clear();
  loop_contacts.clear();
  apparent_volume.clear();
  pore_volume.clear();
  centroid_x.clear();
  centroid_y.clear();
  is_boundary.clear();
  pipe_domain_a.clear();
  pipe_domain_b.clear();
  pipe_contact.clear();
  pipe_length.clear();
  boundary_pipe_domain.clear();
  boundary_pipe_contact.clear();
  boundary_pipe_outer_face.clear();
  boundary_pipe_length.clear();
  boundary_pipe_x.clear();
  boundary_pipe_y.clear();
  outer_offsets.assign(1, 0);
  outer_particles.clear();
  outer_contacts.clear();
  outer_area.clear();
  outer_host_domain.clear();
  euler = EulerCounts{};
  num_pruned_particles = 0;
  num_nonpositive_domains = 0;
  walls.Clear();
}

std::size_t DomainNetwork::MemoryBytes() const {
  return internal::VectorBytes(
             loop_offsets, loop_particles, loop_contacts, apparent_volume, pore_volume, centroid_x,
             centroid_y, is_boundary, pipe_domain_a, pipe_domain_b, pipe_contact, pipe_length,
             boundary_pipe_domain, boundary_pipe_contact, boundary_pipe_outer_face,
             boundary_pipe_length, boundary_pipe_x, boundary_pipe_y, outer_offsets, outer_particles,
             outer_contacts, outer_area, outer_host_domain) +
         walls.MemoryBytes();
}

std::size_t DomainDetector::MemoryBytes() const {
  return internal::VectorBytes(
             degree_, vertex_offsets_, slot_target_, slot_contact_, slot_origin_, slot_angle_,
             alive_, prune_queue_, slot_of_lower_, slot_of_upper_, half_lens_, component_,
             slot_face_, face_offsets_, face_slots_, face_signed_area_, face_sector_area_,
             face_half_lens_, face_centroid_x_, face_centroid_y_, face_component_, face_domain_,
             component_outer_face_, grid_start_, grid_items_, domain_box_, particle_host_) +
         wall_graph_packing_.MemoryBytes() + wall_graph_contacts_.MemoryBytes();
}

namespace {
std::atomic<std::uint64_t> g_domain_detection_calls{0};
}  // namespace

std::uint64_t DomainDetectionCalls() {
  return g_domain_detection_calls.load(std::memory_order_relaxed);
}

Status DomainDetector::Detect(const Packing& packing, const ContactList& contacts,
                              const DomainDetectionOptions& options, DomainNetwork* network) {
  g_domain_detection_calls.fetch_add(1, std::memory_order_relaxed);
  network->Clear();
  hosts_located_ = false;
  SEEP_RETURN_IF_ERROR(CheckInput(packing, contacts));
  BuildGraph(packing, contacts, options);
  Trace(packing, contacts, network);
  return Status::Ok();
}

Status DomainDetector::Detect(const Packing& packing, const ContactList& contacts,
                              std::span<const DetectionWall> walls,
                              const WallContactList& wall_contacts,
                              const DomainDetectionOptions& options, DomainNetwork* network) {
  if (walls.empty()) return Detect(packing, contacts, options, network);
  g_domain_detection_calls.fetch_add(1, std::memory_order_relaxed);
  network->Clear();
  hosts_located_ = false;
  SEEP_RETURN_IF_ERROR(CheckInput(packing, contacts));
  for (std::size_t k = 0; k < wall_contacts.gap.size(); ++k) {
    if (!(wall_contacts.gap[k] <= options.max_gap)) {
      return InvalidArgument("domain detection: wall contact " + std::to_string(k) + " (particle " +
                             std::to_string(wall_contacts.particle[k]) + ", wall " +
                             std::to_string(wall_contacts.wall[k]) + ") has gap " +
                             std::to_string(wall_contacts.gap[k]) + " above max_gap");
    }
  }
  SEEP_RETURN_IF_ERROR(BuildWallGraph(packing, contacts, walls, wall_contacts, &network->walls,
                                      &wall_graph_packing_, &wall_graph_contacts_));
  if (wall_graph_packing_.size() > static_cast<std::size_t>(INT32_MAX) ||
      2 * wall_graph_contacts_.size() > static_cast<std::size_t>(INT32_MAX)) {
    return InvalidArgument("domain detection: too many particles or contacts for 32-bit ids");
  }
  BuildGraph(wall_graph_packing_, wall_graph_contacts_, options);
  Trace(wall_graph_packing_, wall_graph_contacts_, network);
  return Status::Ok();
}

void DomainDetector::Trace(const Packing& packing, const ContactList& contacts,
                           DomainNetwork* network) {
  PruneLowDegree();
  SortAndLinkHalfEdges(packing, contacts);
  LabelComponents();
  TraceFaces(packing, contacts);
  EmitNetwork(packing, contacts, network);
}

Status DomainDetector::CheckInput(const Packing& packing, const ContactList& contacts) const {
  const std::size_t n = packing.size();
  const std::size_t m = contacts.size();
  if (packing.y.size() != n || packing.radius.size() != n) {
    return InvalidArgument("domain detection: packing arrays differ in length");
  }
  if (contacts.j.size() != m || contacts.gap.size() != m) {
    return InvalidArgument("domain detection: contact arrays differ in length");
  }
  if (n > static_cast<std::size_t>(INT32_MAX) || 2 * m > static_cast<std::size_t>(INT32_MAX)) {
    return InvalidArgument("domain detection: too many particles or contacts for 32-bit ids");
  }
  const std::int32_t* ci = contacts.i.data();
  const std::int32_t* cj = contacts.j.data();
  for (std::size_t c = 0; c < m; ++c) {
    const bool ids_ok = ci[c] >= 0 && ci[c] < cj[c] && static_cast<std::size_t>(cj[c]) < n;
    const bool order_ok = c == 0 || ci[c - 1] < ci[c] || (ci[c - 1] == ci[c] && cj[c - 1] < cj[c]);
    if (!ids_ok || !order_ok) {
      return InvalidArgument("domain detection: contact " + std::to_string(c) + " (" +
                             std::to_string(ci[c]) + ", " + std::to_string(cj[c]) +
                             ") must have 0 <= i < j < " + std::to_string(n) +
                             " and follow its predecessor in (i, j) order");
    }
  }
  return Status::Ok();
}

void DomainDetector::BuildGraph(const Packing& packing, const ContactList& contacts,
                                const DomainDetectionOptions& options) {
  const std::size_t n = packing.size();
  const std::size_t m = contacts.size();
  const std::int32_t* ci = contacts.i.data();
  const std::int32_t* cj = contacts.j.data();
  const double* gap = contacts.gap.data();
  max_gap_ = options.max_gap;
  degree_.assign(n, 0);
  half_lens_.resize(m);
  const double* r = packing.radius.data();
  // Radius 0 marks a wall vertex (domain_walls.h): a stretch of wall (two of them) is always an
  // edge, and a foot edge's overlap is the disk's segment beyond the wall, which is half the lens
  // of the disk and its mirror image.
  const auto is_edge = [&](std::size_t c) {
    return gap[c] <= options.max_gap || (r[ci[c]] == 0.0 && r[cj[c]] == 0.0);
  };
  for (std::size_t c = 0; c < m; ++c) {
    // Lenses are needed for every overlapping pair, edge or not (rattlers overlap too).
    const double ri = r[ci[c]];
    const double rj = r[cj[c]];
    half_lens_[c] = rj == 0.0 && gap[c] < 0.0 ? 0.25 * LensArea(ri, ri, 2.0 * (ri + gap[c]))
                                              : HalfPairLens(ri, rj, gap[c]);
    if (is_edge(c)) {
      ++degree_[static_cast<std::size_t>(ci[c])];
      ++degree_[static_cast<std::size_t>(cj[c])];
    }
  }
  vertex_offsets_.resize(n + 1);
  vertex_offsets_[0] = 0;
  for (std::size_t v = 0; v < n; ++v) vertex_offsets_[v + 1] = vertex_offsets_[v] + degree_[v];
  const std::size_t slots = static_cast<std::size_t>(vertex_offsets_[n]);
  slot_target_.resize(slots);
  slot_contact_.resize(slots);
  // prune_queue_ doubles as the fill cursor here; pruning reinitialises it.
  prune_queue_.assign(vertex_offsets_.begin(), vertex_offsets_.end() - 1);
  for (std::size_t c = 0; c < m; ++c) {
    if (!is_edge(c)) continue;
    const std::int32_t a = ci[c];
    const std::int32_t b = cj[c];
    const std::size_t sa = static_cast<std::size_t>(prune_queue_[static_cast<std::size_t>(a)]++);
    const std::size_t sb = static_cast<std::size_t>(prune_queue_[static_cast<std::size_t>(b)]++);
    slot_target_[sa] = b;
    slot_contact_[sa] = static_cast<std::int32_t>(c);
    slot_target_[sb] = a;
    slot_contact_[sb] = static_cast<std::int32_t>(c);
  }
}

void DomainDetector::PruneLowDegree() {
  const std::size_t n = degree_.size();
  alive_.assign(n, 1);
  prune_queue_.clear();
  for (std::size_t v = 0; v < n; ++v) {
    if (degree_[v] <= 1) {
      alive_[v] = 0;
      prune_queue_.push_back(static_cast<std::int32_t>(v));
    }
  }
  // A vertex is marked dead when queued; its live neighbours lose one degree when it is processed.
  for (std::size_t head = 0; head < prune_queue_.size(); ++head) {
    const std::size_t v = static_cast<std::size_t>(prune_queue_[head]);
    for (std::int32_t s = vertex_offsets_[v]; s < vertex_offsets_[v + 1]; ++s) {
      const std::size_t u = static_cast<std::size_t>(slot_target_[static_cast<std::size_t>(s)]);
      if (!alive_[u]) continue;
      if (--degree_[u] <= 1) {
        alive_[u] = 0;
        prune_queue_.push_back(static_cast<std::int32_t>(u));
      }
    }
  }
  if (prune_queue_.empty()) return;
  // Compact the adjacency in place to live edges only (the write cursor never passes the read one).
  std::int32_t write = 0;
  std::int32_t read_begin = vertex_offsets_[0];
  for (std::size_t v = 0; v < n; ++v) {
    const std::int32_t read_end = vertex_offsets_[v + 1];
    vertex_offsets_[v] = write;
    if (alive_[v]) {
      for (std::int32_t s = read_begin; s < read_end; ++s) {
        const std::size_t src = static_cast<std::size_t>(s);
        if (!alive_[static_cast<std::size_t>(slot_target_[src])]) continue;
        slot_target_[static_cast<std::size_t>(write)] = slot_target_[src];
        slot_contact_[static_cast<std::size_t>(write)] = slot_contact_[src];
        ++write;
      }
    }
    read_begin = read_end;
  }
  vertex_offsets_[n] = write;
  slot_target_.resize(static_cast<std::size_t>(write));
  slot_contact_.resize(static_cast<std::size_t>(write));
}

void DomainDetector::SortAndLinkHalfEdges(const Packing& packing, const ContactList& contacts) {
  const std::size_t n = degree_.size();
  const std::size_t slots = slot_target_.size();
  const double* x = packing.x.data();
  const double* y = packing.y.data();
  slot_angle_.resize(slots);
  slot_origin_.resize(slots);
  for (std::size_t v = 0; v < n; ++v) {
    const std::size_t b = static_cast<std::size_t>(vertex_offsets_[v]);
    const std::size_t e = static_cast<std::size_t>(vertex_offsets_[v + 1]);
    for (std::size_t s = b; s < e; ++s) {
      const std::size_t t = static_cast<std::size_t>(slot_target_[s]);
      slot_angle_[s] = std::atan2(y[t] - y[v], x[t] - x[v]);
      slot_origin_[s] = static_cast<std::int32_t>(v);
    }
    // Degrees are small (about 3-6): insertion sort by (angle, neighbour id). The id tie-break
    // makes collinear or coincident neighbours deterministic.
    for (std::size_t s = b + 1; s < e; ++s) {
      const double angle = slot_angle_[s];
      const std::int32_t target = slot_target_[s];
      const std::int32_t contact = slot_contact_[s];
      std::size_t q = s;
      while (q > b && (slot_angle_[q - 1] > angle ||
                       (slot_angle_[q - 1] == angle && slot_target_[q - 1] > target))) {
        slot_angle_[q] = slot_angle_[q - 1];
        slot_target_[q] = slot_target_[q - 1];
        slot_contact_[q] = slot_contact_[q - 1];
        --q;
      }
      slot_angle_[q] = angle;
      slot_target_[q] = target;
      slot_contact_[q] = contact;
    }
  }
  // Twins through the contact: each live contact has one slot at each end.
  slot_of_lower_.assign(contacts.size(), -1);
  slot_of_upper_.assign(contacts.size(), -1);
  for (std::size_t s = 0; s < slots; ++s) {
    const std::size_t c = static_cast<std::size_t>(slot_contact_[s]);
    if (slot_origin_[s] < slot_target_[s]) {
      slot_of_lower_[c] = static_cast<std::int32_t>(s);
    } else {
      slot_of_upper_[c] = static_cast<std::int32_t>(s);
    }
  }
}

void DomainDetector::LabelComponents() {
  const std::size_t n = degree_.size();
  component_.assign(n, -1);
  std::int32_t next_component = 0;
  for (std::size_t root = 0; root < n; ++root) {
    if (!alive_[root] || component_[root] >= 0) continue;
    // Breadth-first flood fill; prune_queue_ is free again and serves as the queue.
    prune_queue_.clear();
    prune_queue_.push_back(static_cast<std::int32_t>(root));
    component_[root] = next_component;
    for (std::size_t head = 0; head < prune_queue_.size(); ++head) {
      const std::size_t v = static_cast<std::size_t>(prune_queue_[head]);
      for (std::int32_t s = vertex_offsets_[v]; s < vertex_offsets_[v + 1]; ++s) {
        const std::size_t u = static_cast<std::size_t>(slot_target_[static_cast<std::size_t>(s)]);
        if (component_[u] >= 0) continue;
        component_[u] = next_component;
        prune_queue_.push_back(static_cast<std::int32_t>(u));
      }
    }
    ++next_component;
  }
  component_outer_face_.assign(static_cast<std::size_t>(next_component), -1);
}

void DomainDetector::TraceFaces(const Packing& packing, const ContactList& contacts) {
  const std::size_t slots = slot_target_.size();
  const double* x = packing.x.data();
  const double* y = packing.y.data();
  const double* r = packing.radius.data();
  const std::int32_t* slot_target = slot_target_.data();
  const std::int32_t* slot_origin = slot_origin_.data();
  const std::int32_t* slot_contact = slot_contact_.data();
  const double* slot_angle = slot_angle_.data();
  const std::int32_t* offsets = vertex_offsets_.data();
  const std::int32_t* lower = slot_of_lower_.data();
  const std::int32_t* upper = slot_of_upper_.data();
  const double* half_lens = half_lens_.data();
  (void)contacts;

  slot_face_.assign(slots, -1);
  face_offsets_.assign(1, 0);
  face_slots_.resize(slots);
  face_signed_area_.clear();
  face_sector_area_.clear();
  face_half_lens_.clear();
  face_centroid_x_.clear();
  face_centroid_y_.clear();
  face_component_.clear();
  // Euler: faces = E - V + 2C; a planar dense packing has about one face per particle.
  const std::size_t expected_faces = slots / 2 + 16;
  face_offsets_.reserve(expected_faces + 1);
  face_signed_area_.reserve(expected_faces);
  face_sector_area_.reserve(expected_faces);
  face_half_lens_.reserve(expected_faces);
  face_centroid_x_.reserve(expected_faces);
  face_centroid_y_.reserve(expected_faces);
  face_component_.reserve(expected_faces);

  std::int32_t* slot_face = slot_face_.data();
  std::int32_t* face_slots = face_slots_.data();
  std::size_t written = 0;
  for (std::size_t start = 0; start < slots; ++start) {
    if (slot_face[start] >= 0) continue;
    const std::int32_t face = static_cast<std::int32_t>(face_signed_area_.size());
    const std::size_t v0 = static_cast<std::size_t>(slot_origin[start]);
    LoopPolygonSums polygon(x[v0], y[v0]);
    double sector = 0.0;
    double lens = 0.0;
    std::int32_t cur = static_cast<std::int32_t>(start);
    do {
      const std::size_t s = static_cast<std::size_t>(cur);
      slot_face[s] = face;
      face_slots[written++] = cur;
      const std::size_t v = static_cast<std::size_t>(slot_origin[s]);
      const std::size_t w = static_cast<std::size_t>(slot_target[s]);
      polygon.AddEdge(x[v], y[v], x[w], y[w]);
      const std::size_t c = static_cast<std::size_t>(slot_contact[s]);
      lens += half_lens[c];
      // Next half-edge: at w, the neighbour immediately clockwise of v, i.e. the slot before the
      // twin (w->v) in w's CCW order. The face angle at w is the CCW sweep from that outgoing
      // edge to w->v.
      const std::int32_t twin = slot_origin[s] < slot_target[s] ? upper[c] : lower[c];
      const std::int32_t first = offsets[w];
      const bool wraps = twin == first;
      const std::int32_t next = wraps ? offsets[w + 1] - 1 : twin - 1;
      double theta = slot_angle[twin] - slot_angle[next];
      if (wraps) theta += 2.0 * std::numbers::pi;
      sector += 0.5 * theta * r[w] * r[w];
      cur = next;
    } while (cur != static_cast<std::int32_t>(start));

    face_offsets_.push_back(static_cast<std::int32_t>(written));
    const double area = polygon.area();
    face_signed_area_.push_back(area);
    face_sector_area_.push_back(sector);
    face_half_lens_.push_back(lens);
    face_centroid_x_.push_back(polygon.centroid_x());
    face_centroid_y_.push_back(polygon.centroid_y());
    const std::int32_t component = component_[v0];
    face_component_.push_back(component);
    // The outer face of a component is its most negative cycle (first one on ties).
    std::int32_t& outer = component_outer_face_[static_cast<std::size_t>(component)];
    if (outer < 0 || area < face_signed_area_[static_cast<std::size_t>(outer)]) outer = face;
  }
}

void DomainDetector::EmitNetwork(const Packing& packing, const ContactList& contacts,
                                 DomainNetwork* network) {
  const std::size_t num_faces = face_signed_area_.size();
  const std::size_t num_components = component_outer_face_.size();
  face_domain_.resize(num_faces);
  for (std::size_t k = 0; k < num_components; ++k) {
    face_domain_[static_cast<std::size_t>(component_outer_face_[k])] =
        -static_cast<std::int32_t>(k) - 1;
  }
  std::size_t num_domains = 0;
  std::size_t domain_loop_length = 0;
  for (std::size_t f = 0; f < num_faces; ++f) {
    if (component_outer_face_[static_cast<std::size_t>(face_component_[f])] ==
        static_cast<std::int32_t>(f)) {
      continue;
    }
    face_domain_[f] = static_cast<std::int32_t>(num_domains++);
    domain_loop_length += static_cast<std::size_t>(face_offsets_[f + 1] - face_offsets_[f]);
  }

  DomainNetwork& net = *network;
  net.loop_offsets.reserve(num_domains + 1);
  net.loop_particles.reserve(domain_loop_length);
  net.loop_contacts.reserve(domain_loop_length);
  net.apparent_volume.reserve(num_domains);
  net.pore_volume.reserve(num_domains);
  net.centroid_x.reserve(num_domains);
  net.centroid_y.reserve(num_domains);
  net.is_boundary.assign(num_domains, 0);

  const std::int32_t* face_slots = face_slots_.data();
  for (std::size_t f = 0; f < num_faces; ++f) {
    if (face_domain_[f] < 0) continue;
    for (std::int32_t k = face_offsets_[f]; k < face_offsets_[f + 1]; ++k) {
      const std::size_t s = static_cast<std::size_t>(face_slots[k]);
      net.loop_particles.push_back(slot_origin_[s]);
      net.loop_contacts.push_back(slot_contact_[s]);
    }
    net.loop_offsets.push_back(static_cast<std::int32_t>(net.loop_particles.size()));
    const double area = face_signed_area_[f];
    net.apparent_volume.push_back(area);
    net.pore_volume.push_back(area - face_sector_area_[f] + face_half_lens_[f]);
    net.centroid_x.push_back(face_centroid_x_[f]);
    net.centroid_y.push_back(face_centroid_y_[f]);
    if (!(area > 0.0)) ++net.num_nonpositive_domains;
  }
  for (std::size_t k = 0; k < num_components; ++k) {
    const std::size_t f = static_cast<std::size_t>(component_outer_face_[k]);
    for (std::int32_t q = face_offsets_[f]; q < face_offsets_[f + 1]; ++q) {
      const std::size_t s = static_cast<std::size_t>(face_slots[q]);
      net.outer_particles.push_back(slot_origin_[s]);
      net.outer_contacts.push_back(slot_contact_[s]);
    }
    net.outer_offsets.push_back(static_cast<std::int32_t>(net.outer_particles.size()));
    net.outer_area.push_back(-face_signed_area_[f]);
    net.outer_host_domain.push_back(-1);
  }

  std::int64_t live_vertices = 0;
  for (const std::uint8_t a : alive_) live_vertices += a;
  net.euler.vertices = live_vertices;
  net.euler.edges = static_cast<std::int64_t>(slot_target_.size() / 2);
  net.euler.cycles = static_cast<std::int64_t>(num_faces);
  net.euler.components = static_cast<std::int64_t>(num_components);
  net.num_pruned_particles = static_cast<std::int64_t>(alive_.size()) - live_vertices;

  hosts_located_ = net.num_pruned_particles > 0 || num_components > 1;
  if (hosts_located_) {
    LocateRattlersAndIslands(packing, contacts, network);
  }

  // Pipes, in ascending contact order.
  const std::size_t m = contacts.size();
  const double* x = packing.x.data();
  const double* y = packing.y.data();
  const double* r = packing.radius.data();
  net.pipe_domain_a.reserve(m);
  net.pipe_domain_b.reserve(m);
  net.pipe_contact.reserve(m);
  net.pipe_length.reserve(m);
  for (std::size_t c = 0; c < m; ++c) {
    const std::int32_t sl = slot_of_lower_[c];
    if (sl < 0) continue;  // not a live edge
    const std::int32_t fa = slot_face_[static_cast<std::size_t>(sl)];
    const std::int32_t fb = slot_face_[static_cast<std::size_t>(slot_of_upper_[c])];
    if (fa == fb) continue;  // bridge: the same face on both sides
    std::int32_t da = face_domain_[static_cast<std::size_t>(fa)];
    std::int32_t db = face_domain_[static_cast<std::size_t>(fb)];
    // An island's outer face is, for flow, the host domain around it.
    if (da < 0 && net.outer_host_domain[static_cast<std::size_t>(-da - 1)] >= 0) {
      da = net.outer_host_domain[static_cast<std::size_t>(-da - 1)];
    }
    if (db < 0 && net.outer_host_domain[static_cast<std::size_t>(-db - 1)] >= 0) {
      db = net.outer_host_domain[static_cast<std::size_t>(-db - 1)];
    }
    const std::size_t i = static_cast<std::size_t>(contacts.i[c]);
    const std::size_t j = static_cast<std::size_t>(contacts.j[c]);
    geometry_internal::AppendContactPipe(net, da, db, static_cast<std::int32_t>(c), i, j,
                                         contacts.gap[c], x, y, r);
  }
}

std::span<const std::int32_t> DomainDetector::pruned_particle_hosts() const {
  if (!hosts_located_) return {};
  return particle_host_;
}

Result<DomainNetwork> DetectDomains(const Packing& packing, const ContactList& contacts,
                                    const DomainDetectionOptions& options) {
  DomainDetector detector;
  DomainNetwork network;
  SEEP_RETURN_IF_ERROR(detector.Detect(packing, contacts, options, &network));
  return network;
}

}  // namespace seep::core
