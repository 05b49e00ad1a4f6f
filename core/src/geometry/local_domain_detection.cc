// Local re-detection (see local_domain_detection.h): a rotation system of the contact graph whose
// faces are re-traced only beside a changed contact, with DomainDetector as the reference and the
// fallback.
#include "seep/core/geometry/local_domain_detection.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "../sizes.h"
#include "contact_pipe.h"
#include "seep/core/geometry/disk_overlap.h"
#include "seep/core/geometry/loop_polygon.h"

namespace seep::core {
namespace {

using internal::Index;

}  // namespace

bool LocalDomainDetector::RotationBefore(std::int32_t a, std::int32_t b) const {
  const double angle_a = he_angle_[Index(a)];
  const double angle_b = he_angle_[Index(b)];
  return angle_a < angle_b || (angle_a == angle_b && Target(a) < Target(b));
}

std::int32_t LocalDomainDetector::CanonicalStart(std::int32_t h) const {
  std::int32_t best = h;
  for (std::int32_t cur = FaceNext(h); cur != h; cur = FaceNext(cur)) {
    const std::int32_t o = Origin(cur);
    const std::int32_t ob = Origin(best);
    if (o < ob || (o == ob && RotationBefore(cur, best))) best = cur;
  }
  return best;
}

Status LocalDomainDetector::Reset(const Packing& packing, const ContactList& contacts,
                                  const DomainDetectionOptions& options) {
  DomainDetector detector;
  DomainNetwork network;
  SEEP_RETURN_IF_ERROR(detector.Detect(packing, contacts, options, &network));
  packing_ = packing;
  options_ = options;
  BuildFrom(contacts, network, detector);
  num_local_updates_ = 0;
  num_full_updates_ = 0;
  last_update_ = Update::kFull;
  return Status::Ok();
}

Status LocalDomainDetector::FullUpdate() {
  ContactList contacts;
  EmitContacts(&contacts);
  DomainDetector detector;
  DomainNetwork network;
  SEEP_RETURN_IF_ERROR(detector.Detect(packing_, contacts, options_, &network));
  BuildFrom(contacts, network, detector);
  last_update_ = Update::kFull;
  ++num_full_updates_;
  return Status::Ok();
}

void LocalDomainDetector::BuildFrom(const ContactList& contacts, const DomainNetwork& network,
                                    const DomainDetector& detector) {
  const std::size_t n = packing_.size();
  const std::size_t m = contacts.size();
  const double* x = packing_.x.data();
  const double* y = packing_.y.data();
  const double* r = packing_.radius.data();

  // Contact c becomes edge c. Some slack, so that the first changes do not move every array.
  const std::size_t slack_edges = m + m / 8 + 64;
  for (auto* v : {&edge_gap_, &edge_half_lens_}) v->reserve(slack_edges);
  edge_in_graph_.reserve(slack_edges);
  for (auto* v : {&he_origin_, &he_next_incident_, &he_ccw_, &he_cw_, &he_face_}) {
    v->reserve(2 * slack_edges);
  }
  he_angle_.reserve(2 * slack_edges);
  edge_gap_.assign(contacts.gap.begin(), contacts.gap.end());
  edge_half_lens_.resize(m);
  edge_in_graph_.assign(m, 0);
  free_edges_.clear();
  he_origin_.resize(2 * m);
  he_next_incident_.resize(2 * m);
  he_ccw_.assign(2 * m, -1);
  he_cw_.assign(2 * m, -1);
  he_angle_.assign(2 * m, 0.0);
  he_face_.assign(2 * m, -1);
  first_incident_.assign(n, -1);
  component_.assign(detector.particle_components().begin(), detector.particle_components().end());
  alive_.resize(n);
  for (std::size_t v = 0; v < n; ++v) alive_[v] = component_[v] >= 0 ? 1 : 0;
  degree_.assign(n, 0);
  for (std::size_t c = m; c-- > 0;) {
    const std::int32_t i = contacts.i[c];
    const std::int32_t j = contacts.j[c];
    const std::int32_t lower = static_cast<std::int32_t>(2 * c);
    he_origin_[2 * c] = i;
    he_origin_[2 * c + 1] = j;
    he_next_incident_[2 * c] = first_incident_[Index(i)];
    first_incident_[Index(i)] = lower;
    he_next_incident_[2 * c + 1] = first_incident_[Index(j)];
    first_incident_[Index(j)] = lower + 1;
    edge_half_lens_[c] = HalfPairLens(r[i], r[j], edge_gap_[c]);
    if (alive_[Index(i)] && alive_[Index(j)] && edge_gap_[c] <= options_.max_gap) {
      edge_in_graph_[c] = 1;
      ++degree_[Index(i)];
      ++degree_[Index(j)];
      he_angle_[2 * c] = std::atan2(y[j] - y[i], x[j] - x[i]);
      he_angle_[2 * c + 1] = std::atan2(y[i] - y[j], x[i] - x[j]);
    }
  }
  // Rotations: each particle's graph half-edges sorted by (angle, target), linked in a ring.
  rotation_first_.assign(n, -1);
  for (std::size_t v = 0; v < n; ++v) {
    if (degree_[v] == 0) continue;
    scratch_.clear();
    for (std::int32_t h = first_incident_[v]; h >= 0; h = he_next_incident_[Index(h)]) {
      if (edge_in_graph_[Index(h >> 1)]) scratch_.push_back(h);
    }
    std::sort(scratch_.begin(), scratch_.end(),
              [this](std::int32_t a, std::int32_t b) { return RotationBefore(a, b); });
    const std::size_t k = scratch_.size();
    for (std::size_t q = 0; q < k; ++q) {
      he_ccw_[Index(scratch_[q])] = scratch_[(q + 1) % k];
      he_cw_[Index(scratch_[q])] = scratch_[(q + k - 1) % k];
    }
    rotation_first_[v] = scratch_[0];
  }

  // Faces: domain d is face d, outer face k is face D + k.
  const std::size_t num_domains = network.num_domains();
  const std::size_t num_outer = network.num_outer_faces();
  const std::size_t faces = num_domains + num_outer;
  const std::size_t slack_faces = faces + faces / 8 + 64;
  for (auto* v : {&face_area_, &face_pore_, &face_centroid_x_, &face_centroid_y_}) {
    v->reserve(slack_faces);
  }
  for (auto* v : {&face_start_, &face_first_held_, &face_islands_, &face_component_}) {
    v->reserve(slack_faces);
  }
  face_kind_.reserve(slack_faces);
  face_kind_.assign(faces, FaceKind::kDomain);
  face_start_.assign(faces, -1);
  face_area_.assign(faces, 0.0);
  face_pore_.assign(faces, 0.0);
  face_centroid_x_.assign(faces, 0.0);
  face_centroid_y_.assign(faces, 0.0);
  face_first_held_.assign(faces, -1);
  face_islands_.assign(faces, 0);
  face_component_.assign(faces, -1);
  free_faces_.clear();
  const auto label_loop = [&](std::size_t f, const std::vector<std::int32_t>& particles,
                              const std::vector<std::int32_t>& loop_contacts, std::int32_t begin,
                              std::int32_t end) {
    for (std::int32_t k = begin; k < end; ++k) {
      const std::size_t c = Index(loop_contacts[Index(k)]);
      const std::int32_t h =
          static_cast<std::int32_t>(2 * c) + (particles[Index(k)] == contacts.i[c] ? 0 : 1);
      he_face_[Index(h)] = static_cast<std::int32_t>(f);
      if (k == begin) face_start_[f] = h;
    }
    face_component_[f] = component_[Index(particles[Index(begin)])];
  };
  for (std::size_t d = 0; d < num_domains; ++d) {
    label_loop(d, network.loop_particles, network.loop_contacts, network.loop_offsets[d],
               network.loop_offsets[d + 1]);
    face_area_[d] = network.apparent_volume[d];
    face_pore_[d] = network.pore_volume[d];
    face_centroid_x_[d] = network.centroid_x[d];
    face_centroid_y_[d] = network.centroid_y[d];
  }
  component_outer_face_.resize(num_outer);
  component_host_face_.resize(num_outer);
  for (std::size_t k = 0; k < num_outer; ++k) {
    const std::size_t f = num_domains + k;
    label_loop(f, network.outer_particles, network.outer_contacts, network.outer_offsets[k],
               network.outer_offsets[k + 1]);
    const std::int32_t host = network.outer_host_domain[k];
    face_kind_[f] = host >= 0 ? FaceKind::kIslandOuter : FaceKind::kOuter;
    face_area_[f] = -network.outer_area[k];
    component_outer_face_[k] = static_cast<std::int32_t>(f);
    component_host_face_[k] = host;
    if (host >= 0) ++face_islands_[Index(host)];
  }
  outside_first_held_ = -1;
  host_face_.assign(n, -1);
  next_held_.assign(n, -1);
  particle_mark_.assign(n, -1);
  tree_nodes_.clear();
  const std::span<const std::int32_t> hosts = detector.pruned_particle_hosts();
  for (std::size_t v = 0; v < hosts.size(); ++v) {
    if (!alive_[v]) HoldParticle(static_cast<std::int32_t>(v), hosts[v]);
  }
  num_nonpositive_domains_ = network.num_nonpositive_domains;
  num_contacts_ = m;
  num_domains_ = num_domains;
  num_graph_edges_ = network.euler.edges;
  num_faces_ = network.euler.cycles;
}

std::int32_t LocalDomainDetector::FindEdge(std::int32_t i, std::int32_t j) const {
  for (std::int32_t h = first_incident_[Index(i)]; h >= 0; h = he_next_incident_[Index(h)]) {
    if (Target(h) == j) return h >> 1;
  }
  return -1;
}

std::int32_t LocalDomainDetector::NewEdge(std::int32_t i, std::int32_t j, double gap) {
  std::int32_t e;
  if (!free_edges_.empty()) {
    e = free_edges_.back();
    free_edges_.pop_back();
  } else {
    e = static_cast<std::int32_t>(edge_gap_.size());
    edge_gap_.push_back(0.0);
    edge_half_lens_.push_back(0.0);
    edge_in_graph_.push_back(0);
    for (int side = 0; side < 2; ++side) {
      he_origin_.push_back(-1);
      he_next_incident_.push_back(-1);
      he_ccw_.push_back(-1);
      he_cw_.push_back(-1);
      he_angle_.push_back(0.0);
      he_face_.push_back(-1);
    }
  }
  const std::size_t k = Index(e);
  const std::int32_t lower = 2 * e;
  edge_gap_[k] = gap;
  edge_half_lens_[k] = HalfPairLens(packing_.radius[Index(i)], packing_.radius[Index(j)], gap);
  edge_in_graph_[k] = 0;
  he_origin_[Index(lower)] = i;
  he_origin_[Index(lower + 1)] = j;
  he_face_[Index(lower)] = -1;  // a reused edge's faces are long gone (their ids may be reused)
  he_face_[Index(lower + 1)] = -1;
  he_next_incident_[Index(lower)] = first_incident_[Index(i)];
  first_incident_[Index(i)] = lower;
  he_next_incident_[Index(lower + 1)] = first_incident_[Index(j)];
  first_incident_[Index(j)] = lower + 1;
  ++num_contacts_;
  return e;
}

void LocalDomainDetector::FreeEdge(std::int32_t e) {
  for (std::int32_t h = 2 * e; h <= 2 * e + 1; ++h) {
    std::int32_t* link = &first_incident_[Index(Origin(h))];
    while (*link != h) link = &he_next_incident_[Index(*link)];
    *link = he_next_incident_[Index(h)];
  }
  if (edge_in_graph_[Index(e)]) {
    UnlinkRotation(2 * e);
    UnlinkRotation(2 * e + 1);
    --degree_[Index(Origin(2 * e))];
    --degree_[Index(Origin(2 * e + 1))];
    --num_graph_edges_;
    edge_in_graph_[Index(e)] = 0;
  }
  free_edges_.push_back(e);
  --num_contacts_;
}

void LocalDomainDetector::LinkRotation(std::int32_t h, std::int32_t after) {
  const std::size_t v = Index(Origin(h));
  if (after < 0) {
    he_ccw_[Index(h)] = h;
    he_cw_[Index(h)] = h;
    rotation_first_[v] = h;
    return;
  }
  const std::int32_t next = he_ccw_[Index(after)];
  he_ccw_[Index(after)] = h;
  he_cw_[Index(h)] = after;
  he_ccw_[Index(h)] = next;
  he_cw_[Index(next)] = h;
  if (RotationBefore(h, rotation_first_[v])) rotation_first_[v] = h;
}

void LocalDomainDetector::UnlinkRotation(std::int32_t h) {
  const std::size_t v = Index(Origin(h));
  const std::int32_t next = he_ccw_[Index(h)];
  const std::int32_t prev = he_cw_[Index(h)];
  if (next == h) {
    rotation_first_[v] = -1;
  } else {
    he_ccw_[Index(prev)] = next;
    he_cw_[Index(next)] = prev;
    if (rotation_first_[v] == h) rotation_first_[v] = next;
  }
  he_ccw_[Index(h)] = -1;
  he_cw_[Index(h)] = -1;
}

std::int32_t LocalDomainDetector::WedgeBefore(std::int32_t v, double angle,
                                              std::int32_t target) const {
  const std::int32_t first = rotation_first_[Index(v)];
  std::int32_t before = he_cw_[Index(first)];  // the last one, when the direction comes first
  std::int32_t h = first;
  do {
    const double a = he_angle_[Index(h)];
    if (!(a < angle || (a == angle && Target(h) < target))) break;
    before = h;
    h = he_ccw_[Index(h)];
  } while (h != first);
  return before;
}

std::int32_t LocalDomainDetector::NewFace() {
  if (!free_faces_.empty()) {
    const std::int32_t f = free_faces_.back();
    free_faces_.pop_back();
    face_kind_[Index(f)] = FaceKind::kDomain;
    face_first_held_[Index(f)] = -1;
    face_islands_[Index(f)] = 0;
    return f;
  }
  face_kind_.push_back(FaceKind::kDomain);
  face_start_.push_back(-1);
  face_area_.push_back(0.0);
  face_pore_.push_back(0.0);
  face_centroid_x_.push_back(0.0);
  face_centroid_y_.push_back(0.0);
  face_first_held_.push_back(-1);
  face_islands_.push_back(0);
  face_component_.push_back(-1);
  return static_cast<std::int32_t>(face_kind_.size() - 1);
}

void LocalDomainDetector::FreeFace(std::int32_t f) {
  face_kind_[Index(f)] = FaceKind::kFree;
  free_faces_.push_back(f);
}

void LocalDomainDetector::TraceFace(std::int32_t seed, std::int32_t f) {
  // The same sums, in the same order, from the same first half-edge as DomainDetector::TraceFaces.
  const std::int32_t start = CanonicalStart(seed);
  const double* x = packing_.x.data();
  const double* y = packing_.y.data();
  const double* r = packing_.radius.data();
  const std::size_t v0 = Index(Origin(start));
  LoopPolygonSums polygon(x[v0], y[v0]);
  double sector = 0.0;
  double lens = 0.0;
  std::int32_t cur = start;
  do {
    he_face_[Index(cur)] = f;
    const std::size_t v = Index(Origin(cur));
    const std::size_t w = Index(Target(cur));
    polygon.AddEdge(x[v], y[v], x[w], y[w]);
    lens += edge_half_lens_[Index(cur >> 1)];
    const std::int32_t twin = Twin(cur);
    const bool wraps = twin == rotation_first_[w];
    const std::int32_t next = he_cw_[Index(twin)];
    double theta = he_angle_[Index(twin)] - he_angle_[Index(next)];
    if (wraps) theta += 2.0 * std::numbers::pi;
    sector += 0.5 * theta * r[w] * r[w];
    cur = next;
  } while (cur != start);

  const std::size_t k = Index(f);
  const double area = polygon.area();
  face_start_[k] = start;
  face_area_[k] = area;
  face_pore_[k] = area - sector + lens;
  face_centroid_x_[k] = polygon.centroid_x();
  face_centroid_y_[k] = polygon.centroid_y();
  face_component_[k] = component_[v0];
}

void LocalDomainDetector::FinishLocal(bool* done) {
  ClearTreeMarks();
  last_update_ = Update::kLocal;
  ++num_local_updates_;
  *done = true;
}

bool LocalDomainDetector::IsOuter(std::int32_t f) const {
  const FaceKind kind = face_kind_[Index(f)];
  return kind == FaceKind::kOuter || kind == FaceKind::kIslandOuter;
}

bool LocalDomainDetector::HoldsIsland(std::int32_t f) const {
  return face_islands_[Index(f)] > 0 || face_kind_[Index(f)] == FaceKind::kIslandOuter;
}

void LocalDomainDetector::HoldParticle(std::int32_t p, std::int32_t f) {
  std::int32_t& first = FirstHeld(f);
  host_face_[Index(p)] = f;
  next_held_[Index(p)] = first;
  first = p;
}

void LocalDomainDetector::MoveHeldParticles(std::int32_t from, std::int32_t to) {
  std::int32_t p = face_first_held_[Index(from)];
  face_first_held_[Index(from)] = -1;
  while (p >= 0) {
    const std::int32_t next = next_held_[Index(p)];
    HoldParticle(p, to);
    p = next;
  }
}

void LocalDomainDetector::CorrectForHeldParticles(std::int32_t f) {
  if (face_first_held_[Index(f)] < 0) return;
  // DomainDetector::LocateRattlersAndIslands, restricted to this host: every held disk in
  // particle order, then every lens of a pruned particle held here in contact order.
  scratch_.clear();
  for (std::int32_t p = face_first_held_[Index(f)]; p >= 0; p = next_held_[Index(p)]) {
    scratch_.push_back(p);
  }
  std::sort(scratch_.begin(), scratch_.end());
  const double* r = packing_.radius.data();
  double& pore = face_pore_[Index(f)];
  for (const std::int32_t p : scratch_) pore -= std::numbers::pi * r[p] * r[p];
  std::vector<std::int32_t>& lenses = id_scratch_;
  lenses.clear();
  for (const std::int32_t p : scratch_) {
    for (std::int32_t h = first_incident_[Index(p)]; h >= 0; h = he_next_incident_[Index(h)]) {
      const std::int32_t e = h >> 1;
      if (edge_half_lens_[Index(e)] == 0.0) continue;
      const std::int32_t i = Origin(2 * e);
      const std::int32_t j = Origin(2 * e + 1);
      const std::int32_t host = !alive_[Index(i)] ? host_face_[Index(i)] : host_face_[Index(j)];
      if (host == f) lenses.push_back(e);
    }
  }
  std::sort(lenses.begin(), lenses.end(), [this](std::int32_t a, std::int32_t b) {
    const std::int32_t ia = Origin(2 * a), ib = Origin(2 * b);
    return ia < ib || (ia == ib && Origin(2 * a + 1) < Origin(2 * b + 1));
  });
  lenses.erase(std::unique(lenses.begin(), lenses.end()), lenses.end());
  for (const std::int32_t e : lenses) pore += 2.0 * edge_half_lens_[Index(e)];
}

Status LocalDomainDetector::RemoveContact(std::int32_t i, std::int32_t j) {
  const std::int32_t n = static_cast<std::int32_t>(packing_.size());
  if (i < 0 || j < 0 || i >= n || j >= n || i == j) {
    return InvalidArgument("local domain detection: contact (" + std::to_string(i) + ", " +
                           std::to_string(j) + ") needs two different particle ids below " +
                           std::to_string(n));
  }
  if (i > j) std::swap(i, j);
  const std::int32_t e = FindEdge(i, j);
  if (e < 0) {
    return InvalidArgument("local domain detection: (" + std::to_string(i) + ", " +
                           std::to_string(j) + ") is not a current contact");
  }
  if (edge_in_graph_[Index(e)]) {
    bool done = false;
    SEEP_RETURN_IF_ERROR(RemoveEdgeLocally(e, &done));  // frees e either way
    return done ? Status::Ok() : FullUpdate();
  }
  // Not an edge. A pruned particle's contacts decide its tree and its lens corrections.
  const bool pruned_end = !alive_[Index(i)] || !alive_[Index(j)];
  const bool matters = pruned_end && (Eligible(e) || edge_half_lens_[Index(e)] != 0.0);
  FreeEdge(e);
  if (!matters) {
    last_update_ = Update::kContactListOnly;
    return Status::Ok();
  }
  bool done = false;
  SEEP_RETURN_IF_ERROR(RemoveTreeContactLocally(i, j, &done));
  return done ? Status::Ok() : FullUpdate();
}

Status LocalDomainDetector::RemoveEdgeLocally(std::int32_t e, bool* done) {
  *done = false;
  const std::int32_t h = 2 * e;
  const std::int32_t t = h + 1;
  const std::int32_t fh = he_face_[Index(h)];
  const std::int32_t ft = he_face_[Index(t)];
  // After h comes, at its target, the neighbour clockwise of t: still in the merged face.
  const std::int32_t seed = he_cw_[Index(t)];
  const std::int32_t i = Origin(h);
  const std::int32_t j = Origin(t);
  FreeEdge(e);
  if (fh == ft || num_nonpositive_domains_ > 0) return Status::Ok();
  if (HoldsIsland(fh) || HoldsIsland(ft)) return Status::Ok();
  const std::int32_t keep = IsOuter(ft) ? ft : fh;
  const std::int32_t drop = keep == fh ? ft : fh;
  FreeFace(drop);
  --num_domains_;
  --num_faces_;

  // The merged face's half-edges, before pruning takes some of them.
  scratch_.clear();
  std::int32_t cur = seed;
  do {
    scratch_.push_back(cur);
    cur = FaceNext(cur);
  } while (cur != seed);
  // Prune down the chains (DomainDetector::PruneLowDegree): each pruned particle's last edge
  // leaves the graph. Its two sides are the merged face, so no other face changes.
  pruned_now_.clear();
  for (const std::int32_t v : {i, j}) {
    if (alive_[Index(v)] && degree_[Index(v)] <= 1) {
      alive_[Index(v)] = 0;
      pruned_now_.push_back(v);
    }
  }
  for (std::size_t head = 0; head < pruned_now_.size(); ++head) {
    const std::int32_t v = pruned_now_[head];
    const std::int32_t g = rotation_first_[Index(v)];
    component_[Index(v)] = -1;
    if (g < 0) continue;
    const std::int32_t k = Target(g);
    UnlinkRotation(g);
    UnlinkRotation(Twin(g));
    edge_in_graph_[Index(g >> 1)] = 0;
    --degree_[Index(v)];
    --num_graph_edges_;
    if (--degree_[Index(k)] <= 1 && alive_[Index(k)]) {
      alive_[Index(k)] = 0;
      pruned_now_.push_back(k);
    }
  }
  std::int32_t survivor = -1;
  for (const std::int32_t g : scratch_) {
    if (he_ccw_[Index(g)] >= 0) {
      survivor = g;
      break;
    }
  }
  if (survivor < 0) return Status::Ok();  // the whole component was pruned: full update
  TraceFace(survivor, keep);

  // What the two faces held, and the newly pruned chains hanging into the merged face.
  const std::int32_t host = IsOuter(keep) ? -1 : keep;
  MoveHeldParticles(drop, host);
  if (host < 0) MoveHeldParticles(keep, host);
  for (const std::int32_t v : pruned_now_) HoldParticle(v, host);
  if (host >= 0) {
    CorrectForHeldParticles(host);
    if (!(face_area_[Index(host)] > 0.0)) return Status::Ok();  // full update
  }
  FinishLocal(done);
  return Status::Ok();
}

Status LocalDomainDetector::AddContact(std::int32_t i, std::int32_t j, double gap) {
  const std::int32_t n = static_cast<std::int32_t>(packing_.size());
  if (i < 0 || j < 0 || i >= n || j >= n || i == j) {
    return InvalidArgument("local domain detection: contact (" + std::to_string(i) + ", " +
                           std::to_string(j) + ") needs two different particle ids below " +
                           std::to_string(n));
  }
  if (!std::isfinite(gap)) {
    return InvalidArgument("local domain detection: contact (" + std::to_string(i) + ", " +
                           std::to_string(j) + ") has a non-finite gap");
  }
  if (i > j) std::swap(i, j);
  if (FindEdge(i, j) >= 0) {
    return InvalidArgument("local domain detection: (" + std::to_string(i) + ", " +
                           std::to_string(j) + ") is already a contact");
  }
  const std::int32_t e = NewEdge(i, j, gap);
  const bool pruned_end = !alive_[Index(i)] || !alive_[Index(j)];
  bool done = false;
  if (pruned_end && (Eligible(e) || edge_half_lens_[Index(e)] != 0.0)) {
    SEEP_RETURN_IF_ERROR(AddTreeContactLocally(e, &done));
  } else if (!Eligible(e)) {
    last_update_ = Update::kContactListOnly;
    return Status::Ok();
  } else {
    SEEP_RETURN_IF_ERROR(AddEdgeLocally(e, &done));
  }
  return done ? Status::Ok() : FullUpdate();
}

Status LocalDomainDetector::AddEdgeLocally(std::int32_t e, bool* done) {
  *done = false;
  const std::int32_t h = 2 * e;
  const std::int32_t t = h + 1;
  const std::int32_t i = Origin(h);
  const std::int32_t j = Origin(t);
  if (component_[Index(i)] != component_[Index(j)] || num_nonpositive_domains_ > 0) {
    return Status::Ok();
  }
  const double* x = packing_.x.data();
  const double* y = packing_.y.data();
  const double angle_h = std::atan2(y[j] - y[i], x[j] - x[i]);
  const double angle_t = std::atan2(y[i] - y[j], x[i] - x[j]);
  const std::int32_t before_h = WedgeBefore(i, angle_h, j);
  const std::int32_t before_t = WedgeBefore(j, angle_t, i);
  const std::int32_t old_face = he_face_[Index(before_h)];
  if (he_face_[Index(before_t)] != old_face || HoldsIsland(old_face)) return Status::Ok();
  const bool was_outer = IsOuter(old_face);
  // What the face held (for the outer face: everything outside all domains) is located again.
  ClearTreeMarks();
  CollectHeld(was_outer ? -1 : old_face);

  he_angle_[Index(h)] = angle_h;
  he_angle_[Index(t)] = angle_t;
  LinkRotation(h, before_h);
  LinkRotation(t, before_t);
  edge_in_graph_[Index(e)] = 1;
  ++degree_[Index(i)];
  ++degree_[Index(j)];
  ++num_graph_edges_;

  const std::int32_t face_h = NewFace();
  const std::int32_t face_t = NewFace();
  FreeFace(old_face);
  TraceFace(h, face_h);
  if (he_face_[Index(t)] == face_h) return Status::Ok();  // not a split: full update
  TraceFace(t, face_t);
  ++num_domains_;
  ++num_faces_;
  const double area_h = face_area_[Index(face_h)];
  const double area_t = face_area_[Index(face_t)];
  if (was_outer) {
    // The outer face is the component's most negative cycle; every domain has a positive area.
    const bool h_outer = area_h < 0.0 && area_t > 0.0;
    const bool t_outer = area_t < 0.0 && area_h > 0.0;
    if (!h_outer && !t_outer) return Status::Ok();
    const std::int32_t outer = h_outer ? face_h : face_t;
    face_kind_[Index(outer)] = FaceKind::kOuter;
    component_outer_face_[Index(face_component_[Index(outer)])] = outer;
  } else if (!(area_h > 0.0) || !(area_t > 0.0)) {
    return Status::Ok();
  }
  const std::int32_t split[] = {face_h, face_t};
  if (!HostTrees(split, was_outer)) return Status::Ok();
  HoldTreeNodes();
  for (const std::int32_t f : split) {
    if (face_kind_[Index(f)] == FaceKind::kDomain) CorrectForHeldParticles(f);
  }
  FinishLocal(done);
  return Status::Ok();
}

namespace {

// Calls visit(edge) for every used edge in ascending (lower id, higher id) order.
template <typename Visit>
void ForEachContactSorted(std::size_t n, const std::vector<std::int32_t>& first_incident,
                          const std::vector<std::int32_t>& next_incident,
                          const std::vector<std::int32_t>& origin,
                          std::vector<std::int32_t>& scratch, Visit&& visit) {
  for (std::size_t v = 0; v < n; ++v) {
    scratch.clear();
    for (std::int32_t h = first_incident[v]; h >= 0; h = next_incident[Index(h)]) {
      if ((h & 1) == 0) scratch.push_back(h);  // v is the lower end
    }
    std::sort(scratch.begin(), scratch.end(), [&](std::int32_t a, std::int32_t b) {
      return origin[Index(a + 1)] < origin[Index(b + 1)];
    });
    for (const std::int32_t h : scratch) visit(h >> 1);
  }
}

}  // namespace

void LocalDomainDetector::EmitContacts(ContactList* contacts) const {
  contacts->Clear();
  contacts->i.reserve(num_contacts_);
  contacts->j.reserve(num_contacts_);
  contacts->gap.reserve(num_contacts_);
  std::vector<std::int32_t> scratch;
  ForEachContactSorted(packing_.size(), first_incident_, he_next_incident_, he_origin_, scratch,
                       [&](std::int32_t e) {
                         contacts->i.push_back(Origin(2 * e));
                         contacts->j.push_back(Origin(2 * e + 1));
                         contacts->gap.push_back(edge_gap_[Index(e)]);
                       });
}

void LocalDomainDetector::Emit(DomainNetwork* network) const {
  DomainNetwork& net = *network;
  net.Clear();
  const std::size_t n = packing_.size();
  const double* x = packing_.x.data();
  const double* y = packing_.y.data();
  const double* r = packing_.radius.data();

  // Contact ids: ranks in the sorted contact list.
  std::vector<std::int32_t> contact_id(edge_gap_.size(), -1);
  std::vector<std::int32_t> sorted_edges;
  sorted_edges.reserve(num_contacts_);
  std::vector<std::int32_t> scratch;
  ForEachContactSorted(n, first_incident_, he_next_incident_, he_origin_, scratch,
                       [&](std::int32_t e) {
                         contact_id[Index(e)] = static_cast<std::int32_t>(sorted_edges.size());
                         sorted_edges.push_back(e);
                       });

  // Faces in DomainDetector's discovery order: by first half-edge, particle then rotation.
  std::vector<std::int32_t> domain_of_face(face_kind_.size(), -1);
  std::vector<std::int32_t> domain_faces;
  domain_faces.reserve(num_domains_);
  std::int64_t cycles = 0;
  std::int64_t live_vertices = 0;
  for (std::size_t v = 0; v < n; ++v) {
    live_vertices += alive_[v];
    const std::int32_t first = rotation_first_[v];
    if (first < 0) continue;
    std::int32_t h = first;
    do {
      const std::int32_t f = he_face_[Index(h)];
      if (face_start_[Index(f)] == h) {
        ++cycles;
        if (face_kind_[Index(f)] == FaceKind::kDomain) {
          domain_of_face[Index(f)] = static_cast<std::int32_t>(domain_faces.size());
          domain_faces.push_back(f);
        }
      }
      h = he_ccw_[Index(h)];
    } while (h != first);
  }

  const auto emit_loop = [&](std::int32_t f, std::vector<std::int32_t>& particles,
                             std::vector<std::int32_t>& loop_contacts) {
    const std::int32_t start = face_start_[Index(f)];
    std::int32_t h = start;
    do {
      particles.push_back(Origin(h));
      loop_contacts.push_back(contact_id[Index(h >> 1)]);
      h = FaceNext(h);
    } while (h != start);
  };
  const std::size_t num_domains = domain_faces.size();
  net.is_boundary.assign(num_domains, 0);
  for (const std::int32_t f : domain_faces) {
    emit_loop(f, net.loop_particles, net.loop_contacts);
    net.loop_offsets.push_back(static_cast<std::int32_t>(net.loop_particles.size()));
    const double area = face_area_[Index(f)];
    net.apparent_volume.push_back(area);
    net.pore_volume.push_back(face_pore_[Index(f)]);
    net.centroid_x.push_back(face_centroid_x_[Index(f)]);
    net.centroid_y.push_back(face_centroid_y_[Index(f)]);
    if (!(area > 0.0)) ++net.num_nonpositive_domains;
  }
  const std::size_t num_components = component_outer_face_.size();
  for (std::size_t k = 0; k < num_components; ++k) {
    const std::int32_t f = component_outer_face_[k];
    emit_loop(f, net.outer_particles, net.outer_contacts);
    net.outer_offsets.push_back(static_cast<std::int32_t>(net.outer_particles.size()));
    net.outer_area.push_back(-face_area_[Index(f)]);
    const std::int32_t host = component_host_face_[k];
    net.outer_host_domain.push_back(host >= 0 ? domain_of_face[Index(host)] : -1);
  }
  net.euler.vertices = live_vertices;
  net.euler.edges = num_graph_edges_;
  net.euler.cycles = cycles;
  net.euler.components = static_cast<std::int64_t>(num_components);
  net.num_pruned_particles = static_cast<std::int64_t>(n) - live_vertices;

  // Pipes, in ascending contact order (DomainDetector::EmitNetwork's rules).
  const auto domain_or_outer = [&](std::int32_t f) -> std::int32_t {
    if (face_kind_[Index(f)] == FaceKind::kDomain) return domain_of_face[Index(f)];
    const std::int32_t k = face_component_[Index(f)];
    const std::int32_t host = component_host_face_[Index(k)];
    return host >= 0 ? domain_of_face[Index(host)] : -k - 1;
  };
  for (std::size_t c = 0; c < sorted_edges.size(); ++c) {
    const std::int32_t e = sorted_edges[c];
    if (!edge_in_graph_[Index(e)]) continue;
    const std::int32_t fa = he_face_[Index(2 * e)];
    const std::int32_t fb = he_face_[Index(2 * e + 1)];
    if (fa == fb) continue;
    const std::int32_t da = domain_or_outer(fa);
    const std::int32_t db = domain_or_outer(fb);
    const std::size_t i = Index(Origin(2 * e));
    const std::size_t j = Index(Origin(2 * e + 1));
    geometry_internal::AppendContactPipe(net, da, db, static_cast<std::int32_t>(c), i, j,
                                         edge_gap_[Index(e)], x, y, r);
  }
}

std::size_t LocalDomainDetector::MemoryBytes() const {
  return packing_.MemoryBytes() +
         internal::VectorBytes(
             edge_gap_, edge_half_lens_, edge_in_graph_, free_edges_, he_origin_, he_next_incident_,
             he_ccw_, he_cw_, he_angle_, he_face_, first_incident_, rotation_first_, degree_,
             alive_, component_, face_kind_, face_start_, face_area_, face_pore_, face_centroid_x_,
             face_centroid_y_, face_first_held_, face_islands_, face_component_, host_face_,
             next_held_, pruned_now_, id_scratch_, particle_mark_, tree_nodes_, tree_hosts_,
             tree_degree_, new_edges_, new_faces_, old_face_edges_, free_faces_,
             component_outer_face_, component_host_face_, scratch_);
}

}  // namespace seep::core
