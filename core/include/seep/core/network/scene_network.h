// SceneNetwork: the pipe network of a scene, built from its packing.
//
// packing -> contacts (gap <= contact_gap_m, plus a round-off tolerance) -> domains and pipes
// (faces of the contact graph) -> FlowNetwork. Node ids of the FlowNetwork are the domain ids of
// the detection, followed by two reservoir nodes with fixed pressure: the inlet at the low end of
// the flow axis and the outlet at the high end (docs/physics.md §2.4, option A). A contact on the
// sample's outer loop whose two particles both lie in the edge layer at one end (their extreme
// coordinate within one mean radius of the sample's end) becomes a pipe from the domain beside it
// to that end's reservoir. The other hull contacts are no-flow.
//
// Radial boundary (BoundarySpec::radial): the packing is cut to an annulus about the well centre;
// the void face enclosing the centre is the well domain (fixed at the well pressure; the smallest
// face enclosing it if several do), every contact of the remaining outer hull is a pipe to one
// outer reservoir node (id = domain count), whose effective radius is the conductance-weighted
// mean distance from the well centre of the interior centroids reflected through the hull contact
// points.
//
// Walls (docs/physics.md §2.4 option B): with a walls effect the pores along the walls are domains
// closed by them (domain_walls.h). A foot (particle-wall contact) carries a pipe like a contact;
// a stretch of an impermeable wall carries none, a stretch of a drained wall is a pipe of
// conductance drain.conductance x its length at detection into that wall's reservoir node (one
// per drained wall, after the other reservoir nodes). Hull contacts where no wall is keep the
// rules above; a walls-only boundary (BoundarySpec::walls_only) has no other reservoir.
//
// Boundary regions (BoundarySpec::regions) come last, on whichever boundary was built: the
// domains it left free whose centroid lies in a region's shape take the region's pressure or
// share its rate (boundary_regions.h). The linear and radial boundaries keep their reservoir
// nodes whatever regions there are: the Darcy geometry below rests on them.
//
// Darcy geometry of the sample, for the permeability k = mu Q L / (H dP):
//   length_m   distance along the axis between the two reservoirs' effective positions. A
//              reservoir pipe stands for the bond to a missing neighbour domain beyond the hull;
//              that neighbour's centroid is taken as the interior domain's centroid reflected
//              through the contact point, and the reservoir sits at the conductance-weighted mean
//              of these images over its pipes. The pressure field is then linear in the axis
//              coordinate through the reservoirs as well as the domains;
//   width_m    area of the domains divided by the distance between the mean contact points of
//              the outlet and inlet hull pipes (the two faces of the flow region).
// On lattices these make k exact (docs/physics.md §1.3): square a^3/(24R) along x and y (reservoirs
// at the particles' outer surfaces, faces through the edge centres); hex a^3/(24 sqrt3 R) along x,
// where the zig-zag ends put the reservoirs half a radius inside the faces' mean line and a band
// of triangles spans 2(columns-1)R. Along y a hex lattice has zig-zag no-flow sides, which a
// linear field does not satisfy, so k there carries a side-wall error of order R/H. On random
// packings both are the natural averages over the irregular ends.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "seep/core/flow/aperture_law.h"
#include "seep/core/flow/flow_network.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {

// A pipe of a linear boundary's flow network that joins an interior domain to the inlet or
// outlet reservoir, with the Darcy geometry it contributes (see above).
struct ReservoirPipe {
  std::size_t pipe = 0;  // index into the FlowNetwork's pipes
  bool inlet = false;    // else the outlet
  double face_m = 0.0;   // axis coordinate of the hull contact point
  double image_m = 0.0;  // axis coordinate of the interior centroid reflected through it
};

// The domains one boundary region holds at a detection (network/boundary_regions.h).
struct RegionNodes {
  std::vector<std::int32_t> nodes;    // the domains it controls, ascending
  double apparent_volume_m2 = 0.0;    // sum V_d over them at detection: a flux region's split
  std::int64_t centroids_inside = 0;  // every domain centroid in its shape, boundary nodes too
};

struct SceneNetwork {
  Packing packing;
  ContactList contacts;
  // The detection: loops, pipes and the volumes the domains were detected with.
  DomainNetwork domains;
  // The live coefficients: volumes (which move with the particles), apertures, pressures. Read
  // volumes here, never from `domains`, once the run has started.
  FlowNetwork flow;
  // Per FlowNetwork pipe: the contact it crosses (interior pipes first, in DomainNetwork order,
  // then the boundary pipes), so callers can refresh apertures from contact forces and gaps: a
  // detection contact id (a wall edge past the contacts, DomainWalls), or -1 for a pipe through a
  // drained wall, whose conductance is the scene's and stays.
  std::vector<std::int32_t> pipe_contact;
  // Walls in the fluid (empty without a walls effect): the wall lines of the detection, in the
  // walls effect's order, the particle-wall contacts it used, and per wall the reservoir node of
  // a drained wall (-1: impermeable).
  std::vector<WallLine> walls;
  WallContactList wall_contacts;
  std::vector<std::int32_t> wall_node;
  // Linear boundary: the pipes to the two reservoirs, in flow-pipe order.
  std::vector<ReservoirPipe> reservoir_pipes;
  std::int32_t inlet_node = -1;
  std::int32_t outlet_node = -1;
  std::int64_t inlet_pipes = 0;
  std::int64_t outlet_pipes = 0;
  double length_m = 0.0;
  double width_m = 0.0;
  double mean_radius_m = 0.0;
  // With fluid weight: the point the weight pressures W = w.(x - origin) are measured from, the
  // centre of the first particle at set-up (kept through re-detections). A point of the sample
  // rather than the scene's origin, taken with no arithmetic: the heads P - W of a sample are then
  // the same bits wherever it sits and however it is turned (a moved sample's uniform heads
  // differed in their last bits, which local damping's sign(v) at v = 0 turned into finite
  // differences), and they keep their digits far from the origin.
  double weight_origin_x_m = 0.0;
  double weight_origin_y_m = 0.0;
  // Radial boundary only (inlet_node, outlet_node and the Darcy geometry stay unset).
  std::int32_t well_domain = -1;  // the hole's domain, held at the well pressure
  // Set by a re-detection on moving particles: a fracture that reaches the hull joins the well to
  // the outside, which then leaves no well domain (well_domain = -1) instead of an error.
  bool well_may_vanish = false;
  // With walls: the well domain reaches a wall (a fracture from the well met the boundary).
  bool well_on_wall = false;
  std::int32_t outer_node = -1;  // the outer reservoir
  std::int64_t outer_pipes = 0;
  double well_x_m = 0.0;  // the well centre (centre of the full packing's bounding box)
  double well_y_m = 0.0;
  double outer_reservoir_radius_m = 0.0;  // effective radius of the outer reservoir
  // Per boundary region of the scene (BoundarySpec::regions, in order): the domains it holds.
  std::vector<RegionNodes> regions;
};

// Builds the packing a scene describes (lattice, random or an explicit list).
Result<Packing> BuildScenePacking(const PackingSpec& spec);

// Builds the network with apertures from the scene's aperture law at zero contact force (a rigid,
// unloaded packing: a = a0 + m g). Free domains start at boundary.initial_pressure_pa. At set-up
// every boundary region must hold a domain (FAILED_PRECONDITION naming it); a re-detection
// (ConnectSceneNetwork alone) lets one be empty.
Result<SceneNetwork> BuildSceneNetwork(const SceneSpec& scene);

// The second half of BuildSceneNetwork, for a re-detection on moved particles: domains, pipes and
// the flow network of net.packing with the contacts in net.contacts (sorted by (i, j), as
// ContactDetector lists them) and the walls in net.walls / net.wall_contacts. The caller sets
// packing, contacts, walls, wall_contacts, mean_radius_m and, for radial scenes, the well centre;
// everything else is rebuilt. Same checks and messages as the build.
Result<SceneNetwork> ConnectSceneNetwork(const SceneSpec& scene, SceneNetwork net);

// Sets the fixed-pressure nodes of `net` (inlet, outlet, a well at fixed pressure, the outer
// reservoir, drained walls' platens) to the pressures `scene` gives them now, as the build did:
// what a stage that changes a boundary pressure needs between re-detections. (The boundary
// regions' pressures and rates: SetRegionConditions, network/boundary_regions.h.)
void SetBoundaryPressures(const SceneSpec& scene, SceneNetwork* net);

// The storage model of a run on `flow`, the network at set-up: the scene's volume and factor, and
// the floor storage_floor_fraction x the mean factor x V of its free and source domains (fixed
// for the run, so a resumed run uses the same).
StorageModel RunStorage(const SceneSpec& scene, const FlowNetwork& flow);

// The scene's aperture law (reference force 1 N/m when the scene leaves it 0, no cap when
// max_aperture_m is 0).
ApertureLaw SceneApertureLaw(const SceneSpec& scene);

// The conductance of the pipe a stretch of `length` of wall `wall` gives into its platen: the
// drain's conductance x the length for a drained wall, 0 for an impermeable one (or no walls).
double WallDrainConductance(const SceneSpec& scene, std::size_t wall, double length);

// The well's pressure, or the outer reservoir's once the well merged into it (breakthrough);
// none without either.
std::optional<double> WellPressure(const SceneNetwork& net);

// The gap of a detection contact id (a wall edge's from the detection's wall table).
double DetectionContactGap(const SceneNetwork& net, std::int32_t contact);

// Largest gap that counts as a contact: packing.contact_gap_m plus a round-off tolerance of
// 1e-9 mean radii (lattice disks that touch in theory sit 1e-16 apart in floating point).
double SceneContactGap(const SceneSpec& scene, double mean_radius_m);

}  // namespace seep::core
