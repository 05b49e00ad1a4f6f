// Domain detection: the fluid domains (closed loops of particles) and pipes of a PFC-style
// pipe network, found as the faces of the planar contact graph (docs/physics.md §2.2).
//
// Graph: vertices are particle centres; edges are the contacts of the input ContactList whose
// gap <= DomainDetectionOptions::max_gap. The algorithm:
//   1. prune vertices of degree <= 1 repeatedly (rattlers, dangling chains: inside a face, not on
//      its boundary);
//   2. sort each vertex's edges by angle atan2(dy, dx), ties broken by neighbour id;
//   3. half-edge u->v is followed by v->w, w = the neighbour of v immediately clockwise from u,
//      which traces every face counter-clockwise (face on the left);
//   4. per connected component, the traced cycle with the most negative signed area is its
//      outer face; every other cycle is a domain;
//   5. a contact whose two half-edges lie in different faces carries a pipe; a bridge (both
//      half-edges in one face) carries none.
//
// Ids and conventions (all ids are 0-based indices):
//   particle id  index into the Packing;
//   contact id   index into the ContactList given to Detect() (not renumbered);
//   domain id    index into the per-domain arrays below, in order of discovery (the face of the
//                lowest unvisited half-edge, half-edges ordered by particle then angle), so
//                re-running detection on the same input gives the same ids in the same order;
//   outer face   index into the per-outer-face arrays, one per connected component.
// Areas ("volumes" per unit thickness) are in length^2 of the packing; lengths in its length.
//
// Volumes of a domain with CCW loop p_0..p_{n-1}:
//   apparent_volume V_d  shoelace area of the polygon through the centres;
//   pore_volume     V_p  V_d - sum_k (theta_k/2) R_k^2 + (overlap lenses counted twice by two
//                        sectors, see below) - (rattlers and islands inside the face),
//                        theta_k = interior angle of the face at p_k, in (0, 2pi), so reflex
//                        vertices (theta > pi) are handled;
//   overlaps: a lens of an overlapping loop contact lies half in each of the two faces beside
//   it and inside both disks' sectors, so half the lens is added back per face side; this makes
//   the solid area count every lens once (triple overlaps are ignored).
//   Rattlers (pruned particles) and their full disk area (minus their own overlap lenses) are
//   removed from the V_p of the domain holding them: a dangling tree takes the face whose wedge
//   at its attachment particle contains the attaching edge; a free rattler or tree takes the
//   smallest domain whose polygon contains its centre (point-in-polygon).
//
// Islands: a component lying inside a domain of another component (found with a point-in-polygon
// test of one of its outer-loop particles; the smallest containing domain wins) makes that domain
// non-simply-connected. The host domain's V_d loses the island's outer-loop area, its V_p loses
// that area plus the island's solid outside its outer loop, and each contact on the island's outer
// loop becomes an ordinary pipe between the island domain beside it and the host domain. The
// host's stored loop stays its outer boundary only. Hence sum V_d over all domains equals the
// sum of the areas of the top-level (non-island) outer loops, and Euler's relation is unchanged.
//
// Boundary pipes: a contact on a top-level outer loop connects the domain beside it to "outside";
// the caller decides by position (e.g. the contact point's x) which reservoir, if any, it drains
// into. Domains beside a top-level outer loop are flagged is_boundary.
//
// Walls (domain_walls.h): with walls, the graph also has wall vertices (ids from the particle
// count on, radius 0) and wall edges (ids from the contact count on); loops, outer walks, pipes
// and boundary pipes then name them like particles and contacts, and `walls` says what they are.
//
// Not done here (left to the scene, docs/physics.md §2.6): merging tiny domains, periodic
// boundaries, mapping pressures across a re-detection. Faces of a non-planar embedding (big
// overlaps crossing other edges) still give a valid, deterministic network, but a domain can then
// have V_d <= 0; `num_nonpositive_domains` counts them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_walls.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/status.h"

namespace seep::core {

struct DomainDetectionOptions {
  // Contacts with gap > max_gap are ignored (not edges). Default: every listed contact is an edge.
  double max_gap = std::numeric_limits<double>::infinity();
};

// Counts of the pruned graph, for Euler's relation V - E + cycles = 2 * components.
struct EulerCounts {
  std::int64_t vertices = 0;    // particles left after pruning
  std::int64_t edges = 0;       // contacts between them
  std::int64_t cycles = 0;      // traced faces: domains + one outer walk per component
  std::int64_t components = 0;  // connected components (counted independently of the faces)
  bool operator==(const EulerCounts&) const = default;
};

struct DomainNetwork {
  // ---- domains (CSR: domain d's loop is entries loop_offsets[d] .. loop_offsets[d+1]-1) ----
  std::vector<std::int32_t> loop_offsets;    // size num_domains() + 1, loop_offsets[0] = 0
  std::vector<std::int32_t> loop_particles;  // CCW particle ids
  // loop_contacts[k] = contact between loop_particles[k] and the next particle of the same loop
  // (cyclically).
  std::vector<std::int32_t> loop_contacts;
  std::vector<double> apparent_volume;  // V_d
  std::vector<double> pore_volume;      // V_p
  std::vector<double> centroid_x;       // centroid of the centre polygon (vertex mean if V_d = 0)
  std::vector<double> centroid_y;
  std::vector<std::uint8_t> is_boundary;  // 1 if beside a top-level outer loop

  // ---- pipes between two domains, one per contact, ascending contact id ----
  // domain_a lies to the left of the directed contact i->j (i < j), domain_b to its right.
  std::vector<std::int32_t> pipe_domain_a;
  std::vector<std::int32_t> pipe_domain_b;
  std::vector<std::int32_t> pipe_contact;
  std::vector<double> pipe_length;  // L = R_i + R_j

  // ---- boundary pipes: a domain and the outside, one per contact on a top-level outer loop ----
  std::vector<std::int32_t> boundary_pipe_domain;
  std::vector<std::int32_t> boundary_pipe_contact;
  std::vector<std::int32_t> boundary_pipe_outer_face;
  std::vector<double> boundary_pipe_length;  // L = R_i + R_j
  // Contact point: on the line of centres, halfway across the gap (or overlap) between surfaces.
  std::vector<double> boundary_pipe_x;
  std::vector<double> boundary_pipe_y;

  // ---- outer faces, one per connected component (CSR like the domain loops) ----
  // The loop is the outer walk, traced clockwise (the unbounded side on its left); a bridge or
  // cut vertex on the hull makes it visit a contact or particle twice.
  std::vector<std::int32_t> outer_offsets;
  std::vector<std::int32_t> outer_particles;
  std::vector<std::int32_t> outer_contacts;
  std::vector<double> outer_area;               // area enclosed by the outer loop (> 0)
  std::vector<std::int32_t> outer_host_domain;  // domain holding this island, -1 if top level

  // ---- the wall vertices and wall edges of a detection with walls (empty otherwise) ----
  DomainWalls walls;

  EulerCounts euler;
  std::int64_t num_pruned_particles = 0;  // rattlers and dangling-chain particles
  std::int64_t num_nonpositive_domains = 0;

  std::size_t num_domains() const { return apparent_volume.size(); }
  std::size_t num_pipes() const { return pipe_contact.size(); }
  std::size_t num_boundary_pipes() const { return boundary_pipe_contact.size(); }
  std::size_t num_outer_faces() const { return outer_area.size(); }
  void Clear();
  std::size_t MemoryBytes() const;
  // Field by field, doubles compared exactly: what "the same network" means for a local
  // re-detection against a full one.
  bool operator==(const DomainNetwork&) const = default;
};

// Rebuilds domains and pipes from contacts. Keep one DomainDetector and call Detect() again after
// every topology change: its buffers (and the network's) are reused, so steady-state calls do not
// allocate. Not thread-safe; use one detector per thread.
// Process-wide count of DomainDetector::Detect calls (instrumentation only, as
// ContactDetectionCalls()).
std::uint64_t DomainDetectionCalls();

class DomainDetector {
 public:
  // `contacts` must be sorted by (i, j) with i < j < packing.size() and no duplicates (what
  // ContactDetector produces); otherwise InvalidArgument naming the offending contact.
  Status Detect(const Packing& packing, const ContactList& contacts,
                const DomainDetectionOptions& options, DomainNetwork* network);
  // With walls: the pores along them are domains closed by the wall segments (domain_walls.h).
  // wall_contacts: sorted by (particle, wall), each with gap <= options.max_gap.
  Status Detect(const Packing& packing, const ContactList& contacts,
                std::span<const DetectionWall> walls, const WallContactList& wall_contacts,
                const DomainDetectionOptions& options, DomainNetwork* network);

  std::size_t MemoryBytes() const;

  // After a Detect without walls, per particle: its connected component in the pruned graph, or
  // -1 if pruned (what LocalDomainDetector starts from).
  std::span<const std::int32_t> particle_components() const { return component_; }
  // After such a Detect, per particle: the domain holding it if pruned, -1 if it is live or lies
  // outside every domain. Empty when nothing was pruned and the graph is connected (nothing was
  // located then).
  std::span<const std::int32_t> pruned_particle_hosts() const;

 private:
  Status CheckInput(const Packing& packing, const ContactList& contacts) const;
  void BuildGraph(const Packing& packing, const ContactList& contacts,
                  const DomainDetectionOptions& options);
  void Trace(const Packing& packing, const ContactList& contacts, DomainNetwork* network);
  void PruneLowDegree();
  void SortAndLinkHalfEdges(const Packing& packing, const ContactList& contacts);
  void LabelComponents();
  void TraceFaces(const Packing& packing, const ContactList& contacts);
  void EmitNetwork(const Packing& packing, const ContactList& contacts, DomainNetwork* network);
  void LocateRattlersAndIslands(const Packing& packing, const ContactList& contacts,
                                DomainNetwork* network);

  // Graph over particles, CSR by vertex; after SortAndLinkHalfEdges slot s is the half-edge
  // slot_origin_[s] -> slot_target_[s], and slots of one vertex are in CCW angular order.
  std::vector<std::int32_t> degree_;
  std::vector<std::int32_t> vertex_offsets_;
  std::vector<std::int32_t> slot_target_;
  std::vector<std::int32_t> slot_contact_;
  std::vector<std::int32_t> slot_origin_;
  std::vector<double> slot_angle_;
  std::vector<std::uint8_t> alive_;          // per particle: survived pruning
  std::vector<std::int32_t> prune_queue_;    // also reused as BFS queue
  std::vector<std::int32_t> slot_of_lower_;  // per contact: slot of half-edge i->j, -1 if none
  std::vector<std::int32_t> slot_of_upper_;  // per contact: slot of half-edge j->i
  std::vector<double> half_lens_;            // per contact: half the overlap lens area
  std::vector<std::int32_t> component_;      // per particle: component id, -1 if pruned

  // Faces (domains and outer walks) in trace order, CSR.
  std::vector<std::int32_t> slot_face_;
  std::vector<std::int32_t> face_offsets_;
  std::vector<std::int32_t> face_slots_;  // outgoing half-edge at each loop position
  std::vector<double> face_signed_area_;
  std::vector<double> face_sector_area_;  // sum (theta/2) R^2 over the face's wedges
  std::vector<double> face_half_lens_;    // sum of half lenses over its edges
  std::vector<double> face_centroid_x_;   // centroid, absolute coordinates
  std::vector<double> face_centroid_y_;
  std::vector<std::int32_t> face_component_;
  std::vector<std::int32_t> face_domain_;  // domain id, or -(outer index) - 1
  std::vector<std::int32_t> component_outer_face_;

  // Point location (only used when there are rattlers or several components).
  std::vector<std::int32_t> grid_start_;
  std::vector<std::int32_t> grid_items_;
  std::vector<double> domain_box_;           // per domain: xmin, ymin, xmax, ymax
  std::vector<std::int32_t> particle_host_;  // per pruned particle: domain holding it, or -1
  std::vector<std::int32_t> pruned_parent_;  // union-find over edges between pruned particles
  bool hosts_located_ = false;               // particle_host_ belongs to the current call
  double max_gap_ = 0.0;                     // edge threshold of the current call
  // The graph with its wall vertices and edges (a detection with walls only).
  Packing wall_graph_packing_;
  ContactList wall_graph_contacts_;
};

// Convenience wrapper with a throw-away detector.
Result<DomainNetwork> DetectDomains(const Packing& packing, const ContactList& contacts,
                                    const DomainDetectionOptions& options = {});

}  // namespace seep::core
