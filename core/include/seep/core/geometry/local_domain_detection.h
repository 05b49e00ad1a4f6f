// Local re-detection: the domain network of a contact graph kept up to date as contacts break
// and form, by re-tracing only the faces beside the changed contact (docs/physics.md §2.2; the
// algorithm and conventions are DomainDetector's, domain_detection.h).
//
// A DomainDetector rebuilds every face: O(particles) per topology change. Here the graph is held
// as a rotation system (per particle, its graph half-edges in CCW order, doubly linked), so a
// change touches only the faces on either side of the contact:
//   - a broken contact with two different faces beside it merges them into one;
//   - a new contact whose two ends open into the same face splits it in two.
// The new faces are traced from their canonical first half-edge (lowest particle, then lowest
// angle), which is where DomainDetector starts them, with the same sums in the same order: their
// volumes and centroids are bit-identical to a full re-detection's, and Emit() writes exactly the
// DomainNetwork that DomainDetector::Detect gives for the current contacts (same ids, same order).
//
// Cases a local patch cannot decide exactly fall back to a full re-detection of the current
// contacts (counted in num_full_updates()):
//   - a broken contact has one face on both sides (a bridge: components change), or its
//     component is pruned away entirely; a new one joins two components, or two different faces
//     (not a planar split), or closes a cycle in a tree hanging from nothing (a new component);
//   - a face beside the change holds an island or is an island's outer face;
//   - a free tree would have to be located outside the faces the change makes;
//   - the network has a domain of non-positive area (a non-planar embedding, where the outer
//     face is chosen by area among all faces), or a new face would be one.
// A broken contact that leaves a particle with one graph edge prunes it, and so on down the chain,
// locally: the chain hangs into the merged face, which then holds it (DomainDetector's rule for a
// tree attached by one edge), and the merged face's V_p gets DomainDetector's corrections for the
// pruned particles it holds, recomputed in DomainDetector's order. Merged faces keep what the two
// faces held; the particles a split face held (for the outer face: every particle outside all
// domains) are located again in the new faces by DomainDetector's rules. A contact that touches a
// pruned tree re-hosts it, or brings the path or cycle it closes back into the graph and splits
// the face it hung in (local_domain_trees.cc). Contacts whose gap is above max_gap (not edges)
// only change the contact list. A free tree is located by point in the faces the change made; so,
// as in DomainDetector, exactness assumes a planar embedding, where faces do not overlap.
//
// Positions are those given to Reset (a copy is kept): the network is that of the packing at
// Reset with the current contacts. Walls are not supported (DomainDetector's wall graph).
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <vector>

#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/status.h"

namespace seep::core {

class LocalDomainDetector {
 public:
  // How the last AddContact/RemoveContact was applied.
  enum class Update { kContactListOnly, kLocal, kFull };

  // Full detection of `contacts` (sorted, as DomainDetector::Detect wants them).
  Status Reset(const Packing& packing, const ContactList& contacts,
               const DomainDetectionOptions& options);

  // The contact (i, j), either order of the ids. InvalidArgument (nothing changed) if it is not
  // a current contact.
  Status RemoveContact(std::int32_t i, std::int32_t j);
  // A new contact (i, j) with surface gap `gap` (negative = overlap). InvalidArgument (nothing
  // changed) for an id out of range, i == j, a non-finite gap or a contact that already exists.
  Status AddContact(std::int32_t i, std::int32_t j, double gap);

  Update last_update() const { return last_update_; }
  std::int64_t num_local_updates() const { return num_local_updates_; }
  std::int64_t num_full_updates() const { return num_full_updates_; }
  std::size_t num_contacts() const { return num_contacts_; }
  std::size_t num_domains() const { return num_domains_; }

  // The current contacts, sorted by (i, j) as ContactDetector gives them. O(contacts).
  void EmitContacts(ContactList* contacts) const;
  // The network DomainDetector::Detect gives for the packing and EmitContacts(). O(particles).
  void Emit(DomainNetwork* network) const;

  std::size_t MemoryBytes() const;

 private:
  enum class FaceKind : std::uint8_t { kFree, kDomain, kOuter, kIslandOuter };

  // Half-edges come in pairs: edge e's half-edges are 2e (lower id -> higher id) and 2e + 1.
  static std::int32_t Twin(std::int32_t h) { return h ^ 1; }
  std::int32_t Origin(std::int32_t h) const { return he_origin_[static_cast<std::size_t>(h)]; }
  std::int32_t Target(std::int32_t h) const { return Origin(Twin(h)); }
  // The next half-edge of h's face: at h's target, the neighbour immediately clockwise of h's
  // origin (DomainDetector's rule; faces are traced CCW, face on the left).
  std::int32_t FaceNext(std::int32_t h) const { return he_cw_[static_cast<std::size_t>(Twin(h))]; }
  // Rotation order at one particle: by angle, then target id (DomainDetector's sort key).
  bool RotationBefore(std::int32_t a, std::int32_t b) const;
  // The canonical first half-edge of the face through h: lowest origin, then rotation order.
  std::int32_t CanonicalStart(std::int32_t h) const;

  Status FullUpdate();
  void BuildFrom(const ContactList& contacts, const DomainNetwork& network,
                 const DomainDetector& detector);
  std::int32_t FindEdge(std::int32_t i, std::int32_t j) const;
  std::int32_t NewEdge(std::int32_t i, std::int32_t j, double gap);
  void FreeEdge(std::int32_t e);
  void LinkRotation(std::int32_t h, std::int32_t after);
  void UnlinkRotation(std::int32_t h);
  // The half-edge at v whose CCW wedge holds direction (angle, target): the last one at or
  // before it in rotation order, cyclically.
  std::int32_t WedgeBefore(std::int32_t v, double angle, std::int32_t target) const;
  std::int32_t NewFace();
  void FreeFace(std::int32_t f);
  // Labels the face through `seed` as f and computes its sums as DomainDetector::TraceFaces does.
  void TraceFace(std::int32_t seed, std::int32_t f);
  bool IsOuter(std::int32_t f) const;
  // A change beside face f cannot be exact: an island's outer face, or a face holding an island.
  bool HoldsIsland(std::int32_t f) const;
  // Domain f's V_p from its traced value, with DomainDetector's corrections for the pruned
  // particles it holds, in the same order (disks by particle id, then lenses by contact).
  void CorrectForHeldParticles(std::int32_t f);
  // Moves the particles held by `from` to `to` (-1: outside every domain).
  void MoveHeldParticles(std::int32_t from, std::int32_t to);
  void HoldParticle(std::int32_t p, std::int32_t f);  // f = -1: outside every domain
  // The first particle held by face f, or outside every domain for f = -1.
  std::int32_t& FirstHeld(std::int32_t f) {
    return f >= 0 ? face_first_held_[static_cast<std::size_t>(f)] : outside_first_held_;
  }
  // Marks and queues in tree_nodes_ the particles face f holds, then takes every marked particle
  // off its host's list (UnholdMarked).
  void CollectHeld(std::int32_t f);

  void FinishLocal(bool* done);                          // counts a local update as done
  Status RemoveEdgeLocally(std::int32_t e, bool* done);  // frees edge e, done or not
  Status AddEdgeLocally(std::int32_t e, bool* done);

  // ---- pruned trees (local_domain_trees.cc) ----
  bool Eligible(std::int32_t e) const {  // an edge of the graph once both ends are live
    return edge_gap_[static_cast<std::size_t>(e)] <= options_.max_gap;
  }
  // Appends to tree_nodes_ the pruned trees holding `seeds` (eligible contacts between pruned
  // particles, not crossing skip_edge), marking each with its index in tree_nodes_.
  void CollectTrees(std::initializer_list<std::int32_t> seeds, std::int32_t skip_edge);
  void ClearTreeMarks();
  // DomainDetector's host of each particle of tree_nodes_ (whole trees, marked) into
  // tree_hosts_: the face of the attachment's wedge, or for a free tree the smallest of
  // `candidates` holding its lowest particle's centre (-1 if none and outside_ok). False if a
  // tree would need locating elsewhere.
  bool HostTrees(std::span<const std::int32_t> candidates, bool outside_ok);
  // The host (domain face, or -1) of a tree hanging from `live` towards `hanging`.
  std::int32_t HostOfWedge(std::int32_t live, std::int32_t hanging) const;
  // DomainDetector's point-in-domain test (bounding box, then even-odd through the centres).
  bool FaceContains(std::int32_t f, double px, double py) const;
  // Takes the marked particles off their hosts' lists.
  void UnholdMarked();
  void HoldTreeNodes();                  // each particle of tree_nodes_ by its tree_hosts_ entry
  void RecomputeDomain(std::int32_t f);  // trace again and correct: bit-identical to a fresh one
  // Takes tree_nodes_ (whole trees) off their hosts, hosts them again (a free one in one of its
  // old hosts) and recomputes every domain that lost or gained one. False: not decidable here.
  bool RehostTrees();
  // A new eligible contact with a pruned end: trees join, attach, or close cycles that come live.
  Status AddTreeContactLocally(std::int32_t e, bool* done);
  // A broken eligible contact (already freed) between a pruned particle and another.
  Status RemoveTreeContactLocally(std::int32_t i, std::int32_t j, bool* done);

  Packing packing_;
  DomainDetectionOptions options_;

  // Edges (one per contact, graph edge or not) and their half-edges.
  std::vector<double> edge_gap_;
  std::vector<double> edge_half_lens_;  // half the overlap lens (0 without overlap)
  std::vector<std::uint8_t> edge_in_graph_;
  std::vector<std::int32_t> free_edges_;
  std::vector<std::int32_t> he_origin_;
  std::vector<std::int32_t> he_next_incident_;  // every contact of the origin, singly linked
  std::vector<std::int32_t> he_ccw_;            // rotation, graph half-edges only
  std::vector<std::int32_t> he_cw_;
  std::vector<double> he_angle_;
  std::vector<std::int32_t> he_face_;

  // Particles.
  std::vector<std::int32_t> first_incident_;
  std::vector<std::int32_t> rotation_first_;  // lowest half-edge in rotation order, -1 if none
  std::vector<std::int32_t> degree_;          // graph degree
  std::vector<std::uint8_t> alive_;           // survived pruning
  std::vector<std::int32_t> component_;       // -1 if pruned
  // A pruned particle's domain face, -1 outside every domain (and for live particles); -2
  // while a change re-hosts it.
  std::vector<std::int32_t> host_face_;
  std::vector<std::int32_t> next_held_;  // the next particle held by the same face

  // Faces (stable ids while they live; freed ids are reused).
  std::vector<FaceKind> face_kind_;
  std::vector<std::int32_t> face_start_;  // canonical first half-edge
  std::vector<double> face_area_;         // signed: V_d of a domain, minus the outer area
  std::vector<double> face_pore_;         // V_p of a domain
  std::vector<double> face_centroid_x_;
  std::vector<double> face_centroid_y_;
  std::vector<std::int32_t> face_first_held_;  // its pruned particles (a list), -1 if none
  std::vector<std::int32_t> face_islands_;     // islands it holds
  std::vector<std::int32_t> face_component_;
  std::vector<std::int32_t> free_faces_;
  std::vector<std::int32_t> component_outer_face_;
  std::vector<std::int32_t> component_host_face_;  // an island's host domain face, or -1

  std::int32_t outside_first_held_ = -1;  // the pruned particles outside every domain (a list)
  std::int64_t num_nonpositive_domains_ = 0;
  std::size_t num_contacts_ = 0;
  std::size_t num_domains_ = 0;
  std::int64_t num_graph_edges_ = 0;
  std::int64_t num_faces_ = 0;
  std::vector<std::int32_t> scratch_;     // half-edges of a face being traced
  std::vector<std::int32_t> pruned_now_;  // particles a broken contact prunes
  // A second scratch list of ids: a face's lens edges, a tree's members, the hosts re-listed.
  std::vector<std::int32_t> id_scratch_;
  std::vector<std::int32_t> particle_mark_;  // per particle: index in tree_nodes_, -1 otherwise
  std::vector<std::int32_t> tree_nodes_;
  std::vector<std::int32_t> tree_hosts_;
  std::vector<std::int32_t> tree_degree_;
  std::vector<std::int32_t> new_edges_;
  std::vector<std::int32_t> new_faces_;
  std::vector<std::int32_t> old_face_edges_;

  Update last_update_ = Update::kFull;
  std::int64_t num_local_updates_ = 0;
  std::int64_t num_full_updates_ = 0;
};

}  // namespace seep::core
