// Local re-detection around pruned trees (see local_domain_detection.h): a contact that touches a
// pruned particle re-hosts the trees it joins or splits, or brings a path or cycle of them back
// into the graph, splitting the face they hung in. Hosts follow DomainDetector's rules
// (domain_inclusions.cc): a tree attached by one edge takes the face of its attachment's wedge, a
// free tree the smallest domain holding its lowest particle's centre.
#include <algorithm>
#include <cmath>

#include "../sizes.h"
#include "seep/core/geometry/local_domain_detection.h"
#include "seep/core/geometry/loop_polygon.h"

namespace seep::core {
namespace {

using internal::Index;

constexpr std::int32_t kUnset = -2;
constexpr std::int32_t kVisiting = -3;

}  // namespace

void LocalDomainDetector::CollectTrees(std::initializer_list<std::int32_t> seeds,
                                       std::int32_t skip_edge) {
  for (const std::int32_t seed : seeds) {
    if (alive_[Index(seed)] || particle_mark_[Index(seed)] >= 0) continue;
    std::size_t head = tree_nodes_.size();
    particle_mark_[Index(seed)] = static_cast<std::int32_t>(head);
    tree_nodes_.push_back(seed);
    for (; head < tree_nodes_.size(); ++head) {
      const std::int32_t v = tree_nodes_[head];
      for (std::int32_t h = first_incident_[Index(v)]; h >= 0; h = he_next_incident_[Index(h)]) {
        const std::int32_t g = h >> 1;
        if (g == skip_edge || !Eligible(g)) continue;
        const std::int32_t u = Target(h);
        if (alive_[Index(u)] || particle_mark_[Index(u)] >= 0) continue;
        particle_mark_[Index(u)] = static_cast<std::int32_t>(tree_nodes_.size());
        tree_nodes_.push_back(u);
      }
    }
  }
}

void LocalDomainDetector::ClearTreeMarks() {
  for (const std::int32_t v : tree_nodes_) particle_mark_[Index(v)] = -1;
  tree_nodes_.clear();
}

std::int32_t LocalDomainDetector::HostOfWedge(std::int32_t live, std::int32_t hanging) const {
  const double* x = packing_.x.data();
  const double* y = packing_.y.data();
  const double angle = std::atan2(y[hanging] - y[live], x[hanging] - x[live]);
  // The last half-edge at or below the angle, cyclically (DomainDetector's scan of the slots).
  const std::int32_t first = rotation_first_[Index(live)];
  std::int32_t slot = he_cw_[Index(first)];
  std::int32_t h = first;
  do {
    if (!(he_angle_[Index(h)] <= angle)) break;
    slot = h;
    h = he_ccw_[Index(h)];
  } while (h != first);
  const std::int32_t f = he_face_[Index(slot)];
  switch (face_kind_[Index(f)]) {
    case FaceKind::kDomain:
      return f;
    case FaceKind::kIslandOuter:
      return component_host_face_[Index(face_component_[Index(f)])];
    default:
      return -1;
  }
}

bool LocalDomainDetector::FaceContains(std::int32_t f, double px, double py) const {
  const double* x = packing_.x.data();
  const double* y = packing_.y.data();
  std::vector<std::int32_t> loop;  // a free tree's location only: rare, not worth a buffer
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  const std::int32_t start = face_start_[Index(f)];
  std::int32_t h = start;
  do {
    const std::int32_t v = Origin(h);
    loop.push_back(v);
    x0 = std::min(x0, x[v]);
    y0 = std::min(y0, y[v]);
    x1 = std::max(x1, x[v]);
    y1 = std::max(y1, y[v]);
    h = FaceNext(h);
  } while (h != start);
  if (px < x0 || py < y0 || px > x1 || py > y1) return false;
  return LoopContains(loop, x, y, px, py);
}

bool LocalDomainDetector::HostTrees(std::span<const std::int32_t> candidates, bool outside_ok) {
  const std::size_t count = tree_nodes_.size();
  tree_hosts_.assign(count, kUnset);
  std::vector<std::int32_t>& members = id_scratch_;
  for (std::size_t k = 0; k < count; ++k) {
    if (tree_hosts_[k] != kUnset) continue;
    if (alive_[Index(tree_nodes_[k])]) {
      tree_hosts_[k] = -1;  // back in the graph: held by nobody
      continue;
    }
    members.assign(1, static_cast<std::int32_t>(k));
    tree_hosts_[k] = kVisiting;
    std::int32_t root = tree_nodes_[k];
    int attachments = 0;
    std::int32_t live = -1;
    std::int32_t hanging = -1;
    for (std::size_t q = 0; q < members.size(); ++q) {
      const std::int32_t w = tree_nodes_[Index(members[q])];
      root = std::min(root, w);
      for (std::int32_t h = first_incident_[Index(w)]; h >= 0; h = he_next_incident_[Index(h)]) {
        if (!Eligible(h >> 1)) continue;
        const std::int32_t u = Target(h);
        if (alive_[Index(u)]) {
          ++attachments;
          live = u;
          hanging = w;
          continue;
        }
        const std::int32_t m = particle_mark_[Index(u)];
        if (m < 0) return false;  // the tree reaches beyond the collected ones
        if (tree_hosts_[Index(m)] == kUnset) {
          tree_hosts_[Index(m)] = kVisiting;
          members.push_back(m);
        }
      }
    }
    std::int32_t host = -1;
    if (attachments == 1) {
      host = HostOfWedge(live, hanging);
    } else if (attachments == 0) {
      const double px = packing_.x[Index(root)];
      const double py = packing_.y[Index(root)];
      for (const std::int32_t f : candidates) {
        if (face_kind_[Index(f)] != FaceKind::kDomain || !FaceContains(f, px, py)) continue;
        if (host < 0 || face_area_[Index(f)] < face_area_[Index(host)]) host = f;
      }
      if (host < 0 && !outside_ok) return false;
    } else {
      return false;  // two attachments would have closed a cycle
    }
    for (const std::int32_t m : members) tree_hosts_[Index(m)] = host;
  }
  return true;
}

void LocalDomainDetector::CollectHeld(std::int32_t f) {
  for (std::int32_t p = FirstHeld(f); p >= 0; p = next_held_[Index(p)]) {
    if (particle_mark_[Index(p)] >= 0) continue;
    particle_mark_[Index(p)] = static_cast<std::int32_t>(tree_nodes_.size());
    tree_nodes_.push_back(p);
  }
  UnholdMarked();
}

void LocalDomainDetector::UnholdMarked() {
  // One pass over each host's list drops its marked particles.
  std::vector<std::int32_t>& hosts = id_scratch_;
  hosts.clear();
  for (const std::int32_t v : tree_nodes_) {
    if (alive_[Index(v)] || host_face_[Index(v)] == kUnset) continue;
    const std::int32_t host = host_face_[Index(v)];
    if (std::find(hosts.begin(), hosts.end(), host) == hosts.end()) hosts.push_back(host);
  }
  for (const std::int32_t host : hosts) {
    std::int32_t* link = &FirstHeld(host);
    while (*link >= 0) {
      const std::int32_t p = *link;
      if (particle_mark_[Index(p)] >= 0) {
        *link = next_held_[Index(p)];
        host_face_[Index(p)] = kUnset;
        next_held_[Index(p)] = -1;
      } else {
        link = &next_held_[Index(p)];
      }
    }
  }
}

void LocalDomainDetector::HoldTreeNodes() {
  for (std::size_t k = 0; k < tree_nodes_.size(); ++k) {
    const std::int32_t v = tree_nodes_[k];
    if (alive_[Index(v)]) {
      host_face_[Index(v)] = -1;  // back in the graph
    } else {
      HoldParticle(v, tree_hosts_[k]);
    }
  }
}

void LocalDomainDetector::RecomputeDomain(std::int32_t f) {
  TraceFace(face_start_[Index(f)], f);
  CorrectForHeldParticles(f);
}

namespace {

void AddOnce(std::vector<std::int32_t>* faces, std::int32_t f) {
  if (f >= 0 && std::find(faces->begin(), faces->end(), f) == faces->end()) faces->push_back(f);
}

}  // namespace

bool LocalDomainDetector::RehostTrees() {
  // A free tree can only lie where its particles were held: in their old hosts.
  new_faces_.clear();
  bool outside = false;
  for (const std::int32_t v : tree_nodes_) {
    const std::int32_t host = host_face_[Index(v)];
    AddOnce(&new_faces_, host);
    outside = outside || host < 0;
  }
  UnholdMarked();
  if (!HostTrees(new_faces_, outside)) return false;
  HoldTreeNodes();
  for (const std::int32_t host : tree_hosts_) AddOnce(&new_faces_, host);
  for (const std::int32_t f : new_faces_) RecomputeDomain(f);
  return true;
}

Status LocalDomainDetector::RemoveTreeContactLocally(std::int32_t i, std::int32_t j, bool* done) {
  *done = false;
  if (num_nonpositive_domains_ > 0) return Status::Ok();
  ClearTreeMarks();
  CollectTrees({i, j}, -1);
  // The trees were one (or hung from a live end): free parts lie in the old host.
  if (RehostTrees()) FinishLocal(done);
  return Status::Ok();
}

Status LocalDomainDetector::AddTreeContactLocally(std::int32_t e, bool* done) {
  *done = false;
  if (num_nonpositive_domains_ > 0) return Status::Ok();
  const std::int32_t a = Origin(2 * e);
  const std::int32_t b = Origin(2 * e + 1);
  ClearTreeMarks();
  CollectTrees({a, b}, e);
  const std::size_t count = tree_nodes_.size();

  // The trees' eligible contacts, the new one included, and the trees' 2-core with the live
  // particles they touch as fixed anchors (DomainDetector::PruneLowDegree on this piece).
  new_edges_.clear();
  tree_degree_.assign(count, 0);
  for (std::size_t k = 0; k < count; ++k) {
    const std::int32_t v = tree_nodes_[k];
    for (std::int32_t h = first_incident_[Index(v)]; h >= 0; h = he_next_incident_[Index(h)]) {
      if (!Eligible(h >> 1)) continue;
      const std::int32_t u = Target(h);
      const std::int32_t m = particle_mark_[Index(u)];
      if (m >= 0 && u < v) continue;  // a contact inside the trees counts from its lower end
      new_edges_.push_back(h >> 1);
      ++tree_degree_[k];
      if (m >= 0) ++tree_degree_[Index(m)];
    }
  }
  std::vector<std::int32_t>& queue = tree_hosts_;
  queue.clear();
  for (std::size_t k = 0; k < count; ++k) {
    if (tree_degree_[k] <= 1) {
      tree_degree_[k] = -1;
      queue.push_back(static_cast<std::int32_t>(k));
    }
  }
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::int32_t v = tree_nodes_[Index(queue[head])];
    for (std::int32_t h = first_incident_[Index(v)]; h >= 0; h = he_next_incident_[Index(h)]) {
      if (!Eligible(h >> 1)) continue;
      const std::int32_t m = particle_mark_[Index(Target(h))];
      if (m < 0 || tree_degree_[Index(m)] < 0) continue;
      if (--tree_degree_[Index(m)] <= 1) {
        tree_degree_[Index(m)] = -1;
        queue.push_back(m);
      }
    }
  }
  const auto survives = [&](std::int32_t v) {
    const std::int32_t m = particle_mark_[Index(v)];
    return m >= 0 ? tree_degree_[Index(m)] >= 0 : alive_[Index(v)] != 0;
  };
  const std::size_t num_survivors = static_cast<std::size_t>(std::count_if(
      tree_degree_.begin(), tree_degree_.end(), [](std::int32_t d) { return d >= 0; }));

  if (num_survivors == 0) {
    // No cycle closed: trees joined, or a tree got (or changed) its attachment. Re-host them.
    if (RehostTrees()) FinishLocal(done);
    return Status::Ok();
  }

  // A path or cycle comes back into the graph. Its edges, and the face they open into at the
  // live particles they join: one face for all of them, or it is not a planar split.
  std::erase_if(new_edges_, [&](std::int32_t g) {
    return !survives(Origin(2 * g)) || !survives(Origin(2 * g + 1));
  });
  const double* x = packing_.x.data();
  const double* y = packing_.y.data();
  std::int32_t face = -1;
  std::int32_t component = -1;
  for (const std::int32_t g : new_edges_) {
    for (std::int32_t hh = 2 * g; hh <= 2 * g + 1; ++hh) {
      const std::int32_t c = Origin(hh);
      if (!alive_[Index(c)]) continue;
      const std::int32_t t = Target(hh);
      const std::int32_t wedge =
          he_face_[Index(WedgeBefore(c, std::atan2(y[t] - y[c], x[t] - x[c]), t))];
      if (face >= 0 && wedge != face) return Status::Ok();
      face = wedge;
      component = component_[Index(c)];
    }
  }
  if (face < 0 || HoldsIsland(face)) return Status::Ok();  // no anchor: a new component
  const bool was_outer = IsOuter(face);
  const std::int32_t expected_host = was_outer ? -1 : face;
  for (const std::int32_t v : tree_nodes_) {
    if (host_face_[Index(v)] != expected_host) return Status::Ok();
  }

  old_face_edges_.clear();
  {
    const std::int32_t start = face_start_[Index(face)];
    std::int32_t h = start;
    do {
      old_face_edges_.push_back(h);
      h = FaceNext(h);
    } while (h != start);
  }
  // Everything the face held (for the outer face: everything outside all domains) is located
  // again, in the faces it splits into; the trees themselves come off their lists too.
  CollectHeld(expected_host);
  for (std::size_t k = 0; k < count; ++k) {
    if (tree_degree_[k] < 0) continue;
    const std::int32_t v = tree_nodes_[k];
    alive_[Index(v)] = 1;
    component_[Index(v)] = component;
  }
  for (const std::int32_t g : new_edges_) {
    const std::int32_t i = Origin(2 * g);
    const std::int32_t j = Origin(2 * g + 1);
    he_angle_[Index(2 * g)] = std::atan2(y[j] - y[i], x[j] - x[i]);
    he_angle_[Index(2 * g + 1)] = std::atan2(y[i] - y[j], x[i] - x[j]);
    he_face_[Index(2 * g)] = -1;
    he_face_[Index(2 * g + 1)] = -1;
    edge_in_graph_[Index(g)] = 1;
    ++degree_[Index(i)];
    ++degree_[Index(j)];
    ++num_graph_edges_;
    for (std::int32_t hh = 2 * g; hh <= 2 * g + 1; ++hh) {
      const std::int32_t v = Origin(hh);
      LinkRotation(hh, rotation_first_[Index(v)] < 0
                           ? -1
                           : WedgeBefore(v, he_angle_[Index(hh)], Target(hh)));
    }
  }
  // Euler: a piece of s particles and s + k edges adds k faces to the one it splits.
  const std::size_t num_new_faces = 1 + new_edges_.size() - num_survivors;
  new_faces_.clear();
  for (std::size_t q = 0; q < num_new_faces; ++q) new_faces_.push_back(NewFace());
  FreeFace(face);
  std::size_t traced = 0;
  for (const std::int32_t g : new_edges_) {
    for (std::int32_t hh = 2 * g; hh <= 2 * g + 1; ++hh) {
      if (he_face_[Index(hh)] >= 0) continue;
      if (traced == num_new_faces) return Status::Ok();  // not a planar split: full update
      TraceFace(hh, new_faces_[traced++]);
    }
  }
  if (traced != num_new_faces) return Status::Ok();
  for (const std::int32_t h : old_face_edges_) {
    if (he_face_[Index(h)] == face) return Status::Ok();
  }
  num_domains_ += num_new_faces - 1;
  num_faces_ += static_cast<std::int64_t>(num_new_faces) - 1;
  if (was_outer) {
    // The outer face is the component's only negative cycle when every domain is positive.
    std::int32_t outer = -1;
    for (const std::int32_t f : new_faces_) {
      const double area = face_area_[Index(f)];
      if (area < 0.0) {
        if (outer >= 0) return Status::Ok();
        outer = f;
      } else if (!(area > 0.0)) {
        return Status::Ok();
      }
    }
    if (outer < 0) return Status::Ok();
    face_kind_[Index(outer)] = FaceKind::kOuter;
    component_outer_face_[Index(component)] = outer;
  } else {
    for (const std::int32_t f : new_faces_) {
      if (!(face_area_[Index(f)] > 0.0)) return Status::Ok();
    }
  }
  if (!HostTrees(new_faces_, was_outer)) return Status::Ok();
  HoldTreeNodes();
  for (const std::int32_t f : new_faces_) {
    if (face_kind_[Index(f)] == FaceKind::kDomain) CorrectForHeldParticles(f);
  }
  FinishLocal(done);
  return Status::Ok();
}

}  // namespace seep::core
