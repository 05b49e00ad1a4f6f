// DemContactForces: disk-disk and disk-wall contacts, parallel bonds, and the Verlet neighbour
// list that finds them. One call per step, AddForces(), adds every contact and bond force to the
// particles.
//
// Pair table. The neighbour list holds every pair (i < j) whose surface gap was below
// skin + flow_gap at the last rebuild, plus every intact bond, SORTED by (i, j). Each entry carries
// the contact state: shear history, current normal force and gap, and its bond if any. An entry is
// a *contact* while its gap < 0 (the disks overlap) or it is bonded; an entry whose disks do not
// touch has zero history (a new contact starts from zero history; a separating one loses it), so
// the sorted list of contacts (CollectContacts) is exactly "the persistent contact list keyed by
// (i, j)" of the design, without inserting or erasing in the hot loop. Disk-wall contacts are kept
// the same way, keyed (i, wall) and sorted. A wall is a line unless SetWallExtents made it a
// segment (dem_wall.h): then the contact is with the segment's nearest point.
//
// Rebuild policy. The list is rebuilt (cell grid of size 2 R_max + skin + flow_gap, O(N)) only
// when some particle has moved more than skin/2, or some wall more than skin/2 along its normal,
// since the last rebuild (so a gap shrinks by at most skin between rebuilds: every pair with
// gap < flow_gap is listed, in particular every overlapping one); the shear histories and bonds are
// carried over by merging the old and new sorted lists. With periodic x, positions are wrapped into
// [x0, x0 + Lx) at each rebuild (only then, so they stay continuous between rebuilds) and pair
// vectors use the nearest image.
//
// Determinism and threads. Forces are computed per pair in parallel into per-pair slots; then each
// particle sums its own pairs in ascending pair order (no atomics, no thread-dependent sums):
// results are bit-identical for any thread count. On one thread each pair adds to its two
// particles' sums as it is computed, in ascending pair order too: the same additions, without
// the slots and gather lists (40 bytes a pair), which only a pass on threads makes. Wall contacts
// and bond-break bookkeeping are serial (they are few).
//
// Flow coupling. After AddForces: CollectContacts() lists contacts with their normal force F
// (> 0 compression) and gap g (> 0 open, for bonded pairs that have separated), and
// broken_bonds() the bonds that broke in this call. CollectFlowContacts() lists the pairs the flow
// network may need (near or bonded) with their gaps, in the geometry area's ContactList form.
//
// Checkpoints. SaveState() copies everything that influences later passes into a
// DemContactState (dem_contact_state.h); RestoreState() validates one and adopts it, so that an
// object created with the same settings continues bit-identically (given the same particles and
// walls).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "seep/core/dem/contact_law.h"
#include "seep/core/dem/dem_contact_state.h"
#include "seep/core/dem/dem_counters.h"
#include "seep/core/dem/dem_particles.h"
#include "seep/core/dem/dem_wall.h"
#include "seep/core/dem/parallel_bond.h"
#include "seep/core/dem/servo_wall.h"
#include "seep/core/geometry/cell_grid.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_walls.h"
#include "seep/core/status.h"

namespace seep::core {

struct DemContactSettings {
  ContactLawParams law;  // disk-disk and disk-wall law
  double skin = 0.0;     // Verlet skin distance (>= 0, same unit as the radii)
  // Largest gap at which CollectFlowContacts must be complete (>= 0): the list also holds the
  // pairs up to this gap, open ones included (they cost one branch-free evaluation per pass).
  double flow_gap = 0.0;
  bool periodic_x = false;  // periodic boundary along x over [x0, x0 + lx)
  double x0 = 0.0;
  double lx = 0.0;  // > 0 when periodic_x; must hold >= 3 grid cells (2 R_max + skin + flow_gap)
};

// "dem.contact.skin: must be finite and >= 0 (got -1)".
Status ValidateDemContactSettings(const DemContactSettings& settings);

// One disk-disk contact as seen by the flow coupling (sorted by (i, j)).
struct DemContactRecord {
  std::int32_t i = 0, j = 0;
  double normal_force = 0.0;  // > 0 compression (contact law + bond normal force)
  double gap = 0.0;           // surface gap, < 0 overlap
  double shear_force = 0.0;   // tangential contact force (history) on i along t
  bool bonded = false;
};

// One disk-wall contact (sorted by (particle, wall)).
struct DemWallContactRecord {
  std::int32_t particle = 0, wall = 0;
  double normal_force = 0.0;
  double gap = 0.0;
  double shear_force = 0.0;
};

class DemContactForces {
 public:
  static Result<DemContactForces> Create(const DemContactSettings& settings);

  // Adds contact and bond forces and torques of the current positions and velocities to
  // particles->fx, fy, torque (the caller clears them first). Rebuilds the neighbour list when
  // needed (and then wraps x when periodic). `walls` may be empty; its size must not change
  // between calls without a ForceRebuild(). dt is the step (for the shear and bond increments).
  Status AddForces(DemParticles* particles, const std::vector<DemWall>& walls, double dt,
                   DemCounters* counters);
  // Same, but the forces and torques are SET (the previous values are discarded), saving the
  // separate ClearForces pass: use it as the first force of a step.
  Status SetForces(DemParticles* particles, const std::vector<DemWall>& walls, double dt,
                   DemCounters* counters);

  // Bonds every pair whose surface gap <= tolerance (tolerance >= 0) with zero initial force
  // and moment. Replaces ALL existing bonds (one BondParams set for the whole assembly); the next
  // force pass rebuilds the list. Returns the number of bonds created.
  Result<std::size_t> BondTouchingPairs(DemParticles* particles, const BondParams& params,
                                        double tolerance, DemCounters* counters);

  // Next AddForces rebuilds the list (after particles or walls were added, moved or replaced).
  void ForceRebuild() { needs_rebuild_ = true; }

  // Makes wall k the segment extents[k] of its line (walls past the end of `extents` stay lines;
  // ValidateWallExtents) and rebuilds at the next pass. Like the settings, the extents are not in
  // the saved state: an object restored for a run with segment walls is given them again.
  Status SetWallExtents(std::vector<DemWallExtent> extents);
  const std::vector<DemWallExtent>& wall_extents() const { return wall_extents_; }

  // Bonds that broke during the last AddForces/SetForces, sorted by (i, j): the event the flow
  // coupling needs to re-detect domains.
  const std::vector<BondBreak>& broken_bonds() const { return broken_; }
  // Per wall: the loads of the last AddForces/SetForces (index = wall index), for servos.
  const std::vector<DemWallLoad>& wall_loads() const { return wall_loads_; }
  std::size_t intact_bond_count() const;

  // The current contacts (overlapping or bonded pairs), sorted by key.
  void CollectContacts(std::vector<DemContactRecord>* out) const;
  void CollectWallContacts(std::vector<DemWallContactRecord>* out) const;

  // The pairs the flow coupling may treat as contacts: every neighbour-list pair whose gap at the
  // last force pass is <= max_gap, plus every pair with an intact bond whatever its gap, sorted
  // by (i, j), with that gap (out is cleared first). Only listed pairs can appear, and the list
  // is complete up to settings().flow_gap, not up to the skin: a pair just outside the cutoff at
  // the last rebuild may since have closed by up to one skin. So callers keep
  // max_gap <= settings().flow_gap (with a larger max_gap some pairs are silently missing).
  // Before the first force pass the list is empty.
  void CollectFlowContacts(double max_gap, ContactList* out) const;
  // Whether CollectFlowContacts(max_gap) would list exactly the pairs (i[m], j[m]), in order,
  // without making the list.
  bool FlowContactsAre(double max_gap, std::span<const std::int32_t> i,
                       std::span<const std::int32_t> j) const;
  // The disk-wall contacts the flow coupling treats as feet of wall pores (domain_walls.h): every
  // listed (particle, wall) whose gap at the last force pass is <= max_gap with the centre on the
  // wall's side (gap > -radius), sorted, with that gap and (if normal_force is given) the normal
  // force of the last pass (0 when open). Complete up to the skin (max_gap <= skin).
  void CollectFlowWallContacts(double max_gap, const DemParticles& particles, WallContactList* out,
                               std::vector<double>* normal_force = nullptr) const;

  // Everything that influences later passes (see dem_contact_state.h), as plain arrays.
  DemContactState SaveState() const;
  // Validates `state` for `particle_count` disks and `wall_count` walls
  // (ValidateDemContactState: DataLoss naming the field) and adopts it; on error the object is
  // unchanged. Afterwards the scratch and the per-particle gather lists are re-derived, and
  // broken_bonds() is empty. Continuing with the particles and walls of the saved run gives
  // bit-identical results to the saved object (the settings must be the same: they are not in
  // the state).
  Status RestoreState(const DemContactState& state, std::size_t particle_count,
                      std::size_t wall_count);

  // Direct reads of the pair table for the flow coupling, which needs the force and gap of the
  // same few pairs at every flow update (an index beats collecting every contact). Indices stay
  // valid while pair_table_version() is unchanged; it changes at every rebuild and restore.
  std::uint64_t pair_table_version() const { return pair_table_version_; }
  // index[m] = the pair of (i[m], j[m]) in the table, or -1 if it is not listed; i, j sorted by
  // (i, j) with i < j (a ContactList). O(pairs + m). InvalidArgument (index untouched) when i
  // and j differ in size or are not sorted.
  Status FindPairs(std::span<const std::int32_t> i, std::span<const std::int32_t> j,
                   std::vector<std::int32_t>* index) const;
  // Normal force of the last pass (> 0 compression; contact law + intact bond; 0 for a listed
  // pair that neither touches nor is bonded) and its gap.
  double pair_normal_force(std::int32_t k) const { return pairs_[static_cast<std::size_t>(k)].fn; }
  double pair_gap(std::int32_t k) const { return pairs_[static_cast<std::size_t>(k)].gap; }

  // Number of pairs in the neighbour list (candidates).
  std::size_t pair_count() const { return pairs_.size(); }
  const DemContactSettings& settings() const { return settings_; }
  // Heap bytes held (capacity).
  std::size_t MemoryBytes() const;

 private:
  explicit DemContactForces(const DemContactSettings& settings) : settings_(settings) {}
  // Rebuild reasons other than particle motion (first call, sizes changed, a wall moved).
  bool NeedsRebuild(const DemParticles& p, const std::vector<DemWall>& walls) const;
  // Copies the disks into packed_ and returns the largest squared displacement since the last
  // rebuild.
  double PackDisks(const DemParticles& p);
  // Lists the walls within `cutoff` (the skin) and the pairs within cutoff + flow_gap.
  Status Rebuild(DemParticles* p, const std::vector<DemWall>& walls, double cutoff,
                 DemCounters* counters);
  // Candidate pairs (i < j, sorted) with gap < cutoff into cand_i, cand_j.
  Status FindCandidatePairs(const DemParticles& p, double cutoff, std::vector<std::int32_t>* cand_i,
                            std::vector<std::int32_t>* cand_j);
  // Computes every pair into its slot (from packed_), gathers the slots into the particles.
  void ComputePairForces(DemParticles* p, double dt, bool overwrite, DemCounters* counters);
  void ComputeWallForces(DemParticles* p, const std::vector<DemWall>& walls, double dt,
                         DemCounters* counters);
  void CollectBondBreaks(DemCounters* counters);
  // Per-particle gather CSR of the pair table for n particles (ascending pair order).
  void BuildGatherLists(std::size_t n);
  // Where disk i stands to wall w (a line or, with an extent, a segment).
  // Wall w is a finite segment (an extent was set for it), not a line.
  bool IsSegment(std::size_t w) const {
    return w < wall_extents_.size() && wall_extents_[w].finite();
  }
  WallGap WallGapOf(const DemParticles& p, std::size_t i, std::size_t w,
                    const std::vector<DemWall>& walls) const;

  DemContactSettings settings_;
  bool needs_rebuild_ = true;
  std::uint64_t pair_table_version_ = 0;
  BondParams bond_params_;

  // One neighbour-list pair and its contact state (48 bytes, one array: the hot loop streams
  // it instead of eight separate arrays).
  struct PairEntry {
    std::int32_t i, j;    // i < j
    std::int32_t bond;    // bond index or -1
    std::int32_t unused;  // padding, kept zero
    double damping;       // normal viscous coefficient c of the pair
    double shear;         // tangential spring force (history)
    double fn;            // normal force of the last evaluation (contact + bond)
    double gap;           // gap of the last evaluation
  };
  // Per-pair results, filled in parallel then gathered per particle (and the value a pair's
  // evaluation returns on one thread).
  struct PairSlot {
    double fx, fy;  // force on i (-f on j)
    double ft;      // tangential force: torque R_i ft on i, R_j ft on j
    double m;       // bond moment: +m on i, -m on j
  };
  // The particle fields the pair loop reads, packed so that one disk is one or two cache lines.
  struct PackedDisk {
    double x, y, vx, vy, omega, r;
  };
  // The rule of CollectFlowContacts and FlowContactsAre: near (gap <= max_gap) or bonded.
  bool IsFlowContact(const PairEntry& e, double max_gap) const {
    const bool bonded = e.bond >= 0 && bond_failure_[e.bond] == BondFailure::kNone;
    return e.gap <= max_gap || bonded;
  }
  // How the flow contacts of a run of pairs compare with a list: they are its entries
  // [start, start + count) (ok), or not (count is then where they stopped matching).
  struct FlowRun {
    std::size_t start = 0, count = 0;
    bool ok = true;
  };
  // The flow contacts of pairs [begin, end) against (i, j) from where the first of them sits in
  // the list (sorted as the pairs are).
  FlowRun MatchFlowRun(double max_gap, std::size_t begin, std::size_t end,
                       std::span<const std::int32_t> i, std::span<const std::int32_t> j) const;
  template <bool kBonds>
  void PairForcesKernel(DemParticles* particles, double dt, bool overwrite, DemCounters* counters);
  Status Evaluate(DemParticles* particles, const std::vector<DemWall>& walls, double dt,
                  bool overwrite, DemCounters* counters);

  // One particle's sums over its pairs on the one-thread path (zero between passes).
  struct PairSums {
    double fx = 0.0, fy = 0.0, ft = 0.0, m = 0.0;
  };

  // Pair table (neighbour list + contact state), sorted by (i, j).
  std::vector<PairEntry> pairs_;
  std::vector<PackedDisk> packed_;
  std::vector<PairSums> sums_;  // one thread: per particle
  // Threads: the slots and the per-particle CSR of pair entries in ascending pair order (k for
  // side i, ~k for side j), made by the first pass on threads after a rebuild or restore.
  bool gather_ready_ = false;
  std::vector<PairSlot> slots_;
  std::vector<std::int32_t> gather_start_, gather_items_;

  // Bonds, sorted by (bond_i_, bond_j_); broken ones are dropped at the next rebuild.
  std::vector<std::int32_t> bond_i_, bond_j_;
  std::vector<double> bond_half_width_;
  std::vector<BondState> bond_state_;
  std::vector<BondFailure> bond_failure_;  // kNone while intact
  std::vector<std::uint8_t> bond_reported_;
  // A bond failed since the last CollectBondBreaks (or a restored state may hold unreported
  // ones): the next one scans the bonds.
  bool unreported_breaks_ = false;
  std::vector<BondBreak> broken_;

  // Wall contacts, sorted by (wall_p_, wall_w_).
  std::vector<std::int32_t> wall_p_, wall_w_;
  std::vector<double> wall_shear_, wall_fn_, wall_gap_;
  std::vector<DemWallLoad> wall_loads_;
  std::vector<DemWallExtent> wall_extents_;  // per wall up to its size; the others are lines

  // Reference positions of the last rebuild.
  std::vector<double> ref_x_, ref_y_;
  std::vector<double> ref_wall_x_, ref_wall_y_;

  // Rebuild scratch (kept to avoid reallocations; the candidate pairs are not: see Rebuild).
  CellGrid grid_;
  std::vector<std::int32_t> row_candidates_;
};

}  // namespace seep::core
