// V_d and V_p of detected domains recomputed from moved particles (see domain_volume_update.h).
// The per-loop arithmetic follows DomainDetector::TraceFaces term by term (same shoelace origin,
// same summation order, same lens formula), so that a bound network reproduces the detector's
// volumes to round-off.
#include "seep/core/coupling/domain_volume_update.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <string>

#include "../parallel_threshold.h"
#include "seep/core/geometry/disk_overlap.h"

namespace seep::core {
namespace {

struct LoopMeasure {
  double signed_area = 0.0;  // shoelace over the centres (> 0 for a CCW loop)
  double pore_terms = 0.0;   // sum over the loop's edges of (half lens - turn term), see Compute
};

// Half the lens of the pair lo < hi with centre offset (dx, dy): ShallowLensArea's (sets *half,
// true) when it covers the pair, as for every DEM contact.
inline bool ShallowHalfLens(double r_lo, double r_hi, double inv_r_lo, double inv_r_hi, double dx,
                            double dy, double* half) {
  double lens = 0.0;
  const bool covered =
      ShallowLensArea(r_lo, r_hi, inv_r_lo, inv_r_hi, std::sqrt(dx * dx + dy * dy), &lens);
  *half = 0.5 * lens;
  return covered;
}

// Half the lens of any pair. A wall vertex (radius 0, domain_walls.h) has the larger id, so it
// is hi: a foot edge's overlap is the disk's segment beyond the wall (half the lens of the disk
// and its mirror image), half of which lies on each side of the edge; a stretch overlaps nothing.
// (The short series of pass 1 cannot take radius 0: 0 x 1/0 flags these edges for this path.)
inline double HalfLens(double r_lo, double r_hi, double dx, double dy) {
  const double d = std::sqrt(dx * dx + dy * dy);
  if (r_hi == 0.0) return r_lo == 0.0 ? 0.0 : 0.25 * LensArea(r_lo, r_lo, 2.0 * d);
  return 0.5 * LensArea(r_lo, r_hi, d);
}

// atan z for |z| <= 1/32: z (1 - z^2/3 + z^4/5 - z^6/7 + z^8/9), whose first omitted term is
// below 3e-18 rad: far under the round-off of the angles it is added to. Estrin's scheme in
// w = -z^2 (a short chain of dependent operations, see disk_overlap.h).
inline double SmallTurn(double z) {
  const double w = -z * z;
  const double w2 = w * w;
  return z *
         (((1.0 + w * (1.0 / 3.0)) + (1.0 / 5.0 + w * (1.0 / 7.0)) * w2) + (1.0 / 9.0) * (w2 * w2));
}

// The angle (-pi, pi] that turns a vector e0 into e, from cross = e0 x e and dot = e0 . e.
// Edges turn little between detections, so the common case is a short series instead of atan2.
constexpr double kSmallTurn = 1.0 / 32.0;
inline double TurnAngle(double cross, double dot) {
  if (dot > 0.0 && std::abs(cross) <= kSmallTurn * dot) return SmallTurn(cross / dot);
  return std::atan2(cross, dot);
}

// kPore = false: the shoelace alone (V_d), with the same summation as kPore = true.
// entry_term[q] = e, or E + e if the loop walks edge e from hi to lo (E edges): the pore term of
// entry q.
// Always inlined: GCC made it a call per domain returning its two sums through the stack, and
// the short loops (four or five entries) of the next domains could not start until it returned.
template <bool kPore>
[[gnu::always_inline]] inline LoopMeasure MeasureLoop(const ParticleView& p,
                                                      const std::int32_t* loop,
                                                      const std::int32_t* entry_term,
                                                      const double* term, std::size_t begin,
                                                      std::size_t end) {
  LoopMeasure m;
  if (end <= begin) return m;
  const double* x = p.x.data();
  const double* y = p.y.data();
  const std::size_t v0 = static_cast<std::size_t>(loop[begin]);
  const double x0 = x[v0];
  const double y0 = y[v0];
  // Shoelace relative to the first vertex, as the detector, to keep precision far from 0; each
  // centre is read once (the head of one edge is the tail of the next).
  double ax = 0.0, ay = 0.0;
  double twice_area = 0.0;
  for (std::size_t q = begin; q < end; ++q) {
    const std::size_t w = static_cast<std::size_t>(loop[q + 1 < end ? q + 1 : begin]);
    const double bx = x[w] - x0, by = y[w] - y0;
    twice_area += ax * by - bx * ay;
    ax = bx;
    ay = by;
    if constexpr (kPore) m.pore_terms += term[entry_term[q]];
  }
  m.signed_area = 0.5 * twice_area;
  return m;
}

Status CheckVolumeNetworkIds(std::span<const std::int32_t> ids, std::size_t n, const char* field) {
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] < 0 || static_cast<std::size_t>(ids[k]) >= n) {
      return InvalidArgument(std::string("coupling.domain_volume.network.") + field + "[" +
                             std::to_string(k) + "]: particle id " + std::to_string(ids[k]) +
                             " is not in [0, " + std::to_string(n) + ")");
    }
  }
  return Status::Ok();
}

}  // namespace

Status DomainVolumeUpdater::Check(const ParticleView& particles, const DomainNetwork& network,
                                  std::size_t volumes) const {
  SEEP_RETURN_IF_ERROR(CheckParticleView(particles, "coupling.domain_volume.particles"));
  if (bound_particles_ != 0 && particles.size() != bound_particles_) {
    return FailedPrecondition(
        "coupling.domain_volume.particles: " + std::to_string(particles.size()) +
        " particles, the updater was " + "bound with " + std::to_string(bound_particles_) +
        " (call Bind after every detection)");
  }
  const std::size_t num_domains = network.num_domains();
  if (volumes != num_domains) {
    return InvalidArgument("coupling.domain_volume: volume arrays have " + std::to_string(volumes) +
                           " entries, expected " + std::to_string(num_domains) +
                           " (one per domain)");
  }
  if (network.loop_offsets.size() != num_domains + 1 ||
      static_cast<std::size_t>(network.loop_offsets.back()) != network.loop_particles.size() ||
      network.outer_offsets.size() != network.num_outer_faces() + 1 ||
      static_cast<std::size_t>(network.outer_offsets.back()) != network.outer_particles.size() ||
      network.outer_host_domain.size() != network.num_outer_faces()) {
    return InvalidArgument("coupling.domain_volume.network: loop offsets do not match the loops");
  }
  for (const std::int32_t host : network.outer_host_domain) {
    if (host >= static_cast<std::int32_t>(num_domains)) {
      return InvalidArgument("coupling.domain_volume.network.outer_host_domain: domain " +
                             std::to_string(host) + " out of range");
    }
  }
  return Status::Ok();
}

// V_p = V_d - sector + sum of half lenses, with sector = sum_w (theta_w/2) R_w^2 over the wedges.
// theta_w is its value at Bind plus the turn of the edge into w minus the turn of the edge out of
// it, so regrouped per edge: sector = sector0 + sum_edges dir (turn/2)(R_hi^2 - R_lo^2), where
// sector0 is the sector sum at Bind and dir = +1 where the loop walks the edge lo -> hi. Each edge
// carries one term per direction (ComputeEdgeTerms) and each loop entry adds one of them.
template <bool kPore>
void DomainVolumeUpdater::ComputeGeometric(const ParticleView& particles,
                                           const DomainNetwork& network, const SectorSums& sectors,
                                           std::span<double> apparent_volume,
                                           std::span<double> pore_volume) const {
  const double* term = edge_term_.data();
  const std::int32_t* loops = network.loop_particles.data();
  const auto domains = static_cast<std::ptrdiff_t>(network.num_domains());
  // Per domain writes only: threads change no bit. (The islands below write their hosts.)
  internal::RunOnCoreThreads(domains, [&](const internal::TeamMember& member) {
    const auto [first, last] = member.Share(domains);
    for (std::ptrdiff_t d = first; d < last; ++d) {
      const LoopMeasure m =
          MeasureLoop<kPore>(particles, loops, loop_entry_term_.data(), term,
                             static_cast<std::size_t>(network.loop_offsets[d]),
                             static_cast<std::size_t>(network.loop_offsets[d + 1]));
      apparent_volume[d] = m.signed_area;
      if constexpr (kPore)
        pore_volume[d] = m.signed_area - sectors.loop[static_cast<std::size_t>(d)] + m.pore_terms;
    }
  });
  // Islands: the host loses the area inside the island's outer walk (traced clockwise, so its
  // signed area is negative) and, from V_p, the island's solid outside that walk.
  const std::int32_t* outer = network.outer_particles.data();
  for (std::size_t k = 0; k < network.num_outer_faces(); ++k) {
    const std::int32_t host = network.outer_host_domain[k];
    if (host < 0) continue;
    const LoopMeasure m =
        MeasureLoop<kPore>(particles, outer, outer_entry_term_.data(), term,
                           static_cast<std::size_t>(network.outer_offsets[k]),
                           static_cast<std::size_t>(network.outer_offsets[k + 1]));
    const double inside = -m.signed_area;
    apparent_volume[static_cast<std::size_t>(host)] -= inside;
    if constexpr (kPore) {
      pore_volume[static_cast<std::size_t>(host)] -= inside + (sectors.outer[k] - m.pore_terms);
    }
  }
}

namespace {

// The face angle at Bind at the head w of loop entry q (tail v, next entry's head u): the CCW
// sweep from the outgoing edge w->u to the incoming edge's reverse w->v, in [0, 2 pi), which
// handles reflex vertices; one atan2 of (cross, dot) instead of the detector's difference of two
// edge angles, the same angle to round-off. Made from the edge vectors at Bind and the entries'
// terms rather than held per entry (8 bytes an entry, about 48 a particle), with the very vectors
// of the bind positions: an edge holds x[hi] - x[lo], and x[lo] - x[hi] is exactly
// 0 - (x[hi] - x[lo]) (+0 for equal coordinates too, where -(x[hi] - x[lo]) would be -0).
double BindWedgeAngle(std::int32_t entry_term, std::int32_t next_entry_term, std::int32_t edges,
                      const double* x0, const double* y0) {
  // An entry below `edges` walks its edge lo -> hi; the angle's "in" vector points back along it.
  const bool back = entry_term < edges, next_forward = next_entry_term < edges;
  const auto e = static_cast<std::size_t>(back ? entry_term : entry_term - edges);
  const auto e1 =
      static_cast<std::size_t>(next_forward ? next_entry_term : next_entry_term - edges);
  const double in_x = back ? 0.0 - x0[e] : x0[e], in_y = back ? 0.0 - y0[e] : y0[e];
  const double out_x = next_forward ? x0[e1] : 0.0 - x0[e1];
  const double out_y = next_forward ? y0[e1] : 0.0 - y0[e1];
  double theta = std::atan2(out_x * in_y - out_y * in_x, out_x * in_x + out_y * in_y);
  if (theta < 0.0) theta += 2.0 * std::numbers::pi;
  return theta;
}

// Sector sum at the Bind angles with the radii r, per face (CSR offsets over the loop entries).
void SectorsAtBind(std::span<const std::int32_t> offsets, std::span<const std::int32_t> loop,
                   const std::vector<std::int32_t>& entry_term, std::int32_t edges,
                   const double* x0, const double* y0, const double* r, std::vector<double>* out) {
  out->assign(offsets.empty() ? 0 : offsets.size() - 1, 0.0);
  for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
    const auto begin = static_cast<std::size_t>(offsets[f]);
    const auto end = static_cast<std::size_t>(offsets[f + 1]);
    double sector = 0.0;
    for (std::size_t q = begin; q < end; ++q) {
      const std::size_t q1 = q + 1 < end ? q + 1 : begin;
      const auto w = static_cast<std::size_t>(loop[q1]);
      const double theta0 = BindWedgeAngle(entry_term[q], entry_term[q1], edges, x0, y0);
      sector += 0.5 * theta0 * r[w] * r[w];
    }
    (*out)[f] = sector;
  }
}

}  // namespace

DomainVolumeUpdater::SectorSums DomainVolumeUpdater::Sectors(const ParticleView& particles,
                                                             const DomainNetwork& network) const {
  // Bitwise (memcmp streams at memory speed; an element loop was a serial 10 us a step on the
  // bench bed): radii are positive (wall vertices +0), never -0 or NaN, so equal bits and equal
  // values are the same thing.
  if (particles.radius.size() == bind_radius_.size() &&
      (bind_radius_.empty() || std::memcmp(particles.radius.data(), bind_radius_.data(),
                                           bind_radius_.size() * sizeof(double)) == 0)) {
    return SectorSums{bind_loop_sector_, bind_outer_sector_, true};
  }
  SectorsAtBind(network.loop_offsets, network.loop_particles, loop_entry_term_, NumEdges(),
                edge_x0_.data(), edge_y0_.data(), particles.radius.data(), &loop_sector_);
  SectorsAtBind(network.outer_offsets, network.outer_particles, outer_entry_term_, NumEdges(),
                edge_x0_.data(), edge_y0_.data(), particles.radius.data(), &outer_sector_);
  return SectorSums{loop_sector_, outer_sector_, false};
}

void DomainVolumeUpdater::ComputeEdgeTerms(const ParticleView& particles, bool bind_radii) const {
  // 1/R from Bind while the radii are those of Bind (a DEM's are), else divided afresh.
  if (bind_radii) {
    ComputeEdgeTermsWith<true>(particles);
  } else {
    ComputeEdgeTermsWith<false>(particles);
  }
}

namespace {

// Edges per block of ComputeEdgeTermsWith: the block's gathered inputs and flags (5 arrays of
// doubles, 10 kB) live on the stack and stay in L1 between the passes, where a per-edge scratch
// held 40 bytes an edge (about 120 a particle of a hex lattice) for the whole run.
constexpr std::ptrdiff_t kEdgeBlock = 256;

// What EdgeTermsBlock reads: per particle, the current positions and radii; per edge, its
// particles, its vector and (kBindRadii) its 1/R at Bind.
struct EdgeInputs {
  const double* x;
  const double* y;
  const double* r;
  const std::int32_t* lo;
  const std::int32_t* hi;
  const double* x0;
  const double* y0;
  const double* inv_r_lo;  // kBindRadii only
  const double* inv_r_hi;
};

// The terms of edges [begin, begin + count), count <= kEdgeBlock. Writes per edge only.
template <bool kBindRadii>
void EdgeTermsBlock(const EdgeInputs& in, std::ptrdiff_t begin, std::ptrdiff_t count,
                    double* __restrict forward, double* __restrict backward) {
  alignas(64) double gx[kEdgeBlock], gy[kEdgeBlock], g_lo[kEdgeBlock], g_hi[kEdgeBlock];
  alignas(64) double slow[kEdgeBlock];
  const std::int32_t* __restrict lo_of = in.lo + begin;
  const std::int32_t* __restrict hi_of = in.hi + begin;
  const double* __restrict x0 = in.x0 + begin;
  const double* __restrict y0 = in.y0 + begin;
  const double* __restrict inv_lo = in.inv_r_lo + begin;
  const double* __restrict inv_hi = in.inv_r_hi + begin;
  forward += begin;
  backward += begin;
  // Pass 0 gathers what each edge reads into contiguous arrays (no gathers in SSE2 vectors).
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    const std::ptrdiff_t lo = lo_of[k], hi = hi_of[k];
    gx[k] = in.x[hi] - in.x[lo];
    gy[k] = in.y[hi] - in.y[lo];
    g_lo[k] = in.r[lo];
    g_hi[k] = in.r[hi];
  }
  // Pass 1, branch-free so that it vectorises: every edge as if it took the short series of
  // both TurnAngle and HalfLens; the edges outside their range are flagged.
#pragma omp simd
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    const double dx = gx[k];
    const double dy = gy[k];
    const double cross = x0[k] * dy - y0[k] * dx;
    const double dot = x0[k] * dx + y0[k] * dy;
    // Bitwise & on the conditions: no short-circuit branches in the vector loop.
    const bool turn_ok = (dot > 0.0) & (std::abs(cross) <= kSmallTurn * dot);
    const double turn = SmallTurn(cross / std::max(dot, 1e-300));
    const double r_lo = g_lo[k], r_hi = g_hi[k];
    double half_lens = 0.0;
    const bool lens_ok = ShallowHalfLens(r_lo, r_hi, kBindRadii ? inv_lo[k] : 1.0 / r_lo,
                                         kBindRadii ? inv_hi[k] : 1.0 / r_hi, dx, dy, &half_lens);
    const double sector_turn = 0.5 * turn * (r_hi * r_hi - r_lo * r_lo);
    forward[k] = half_lens - sector_turn;       // walked lo -> hi
    backward[k] = half_lens + sector_turn;      // walked hi -> lo
    slow[k] = (turn_ok & lens_ok) ? 0.0 : 1.0;  // a double: a byte store stops the vectoriser
  }
  // Pass 2: the flagged few (a large turn since Bind, a deep overlap; every edge of a wall
  // vertex) with atan2 and LensArea.
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    if (slow[k] == 0.0) continue;
    const double dx = gx[k];
    const double dy = gy[k];
    const double turn = TurnAngle(x0[k] * dy - y0[k] * dx, x0[k] * dx + y0[k] * dy);
    const double r_lo = g_lo[k], r_hi = g_hi[k];
    const double half_lens = HalfLens(r_lo, r_hi, dx, dy);
    const double sector_turn = 0.5 * turn * (r_hi * r_hi - r_lo * r_lo);
    forward[k] = half_lens - sector_turn;
    backward[k] = half_lens + sector_turn;
  }
}

}  // namespace

template <bool kBindRadii>
void DomainVolumeUpdater::ComputeEdgeTermsWith(const ParticleView& particles) const {
  const EdgeInputs in{particles.x.data(), particles.y.data(),    particles.radius.data(),
                      edge_lo_.data(),    edge_hi_.data(),       edge_x0_.data(),
                      edge_y0_.data(),    edge_inv_r_lo_.data(), edge_inv_r_hi_.data()};
  double* term = edge_term_.data();
  const auto edges = static_cast<std::ptrdiff_t>(edge_lo_.size());
  const std::ptrdiff_t blocks = (edges + kEdgeBlock - 1) / kEdgeBlock;
  // Every block writes its own edges only: threads change no bit. Each member takes a contiguous
  // share of the blocks: edges come in domain order and domains in particle order, so a member
  // mostly reads the positions its own core has just integrated. Blocks dealt one at a time (to
  // spread the flagged edges, which cluster along walls) made every member read the other core's
  // fresh positions: 93-118 us a pass on the settled bed on two threads, 72-81 us in halves (one
  // thread: 131-136 us); the fracturing scenes gained too.
  internal::RunOnCoreThreads(edges, [&](const internal::TeamMember& member) {
    const auto [first_block, last_block] = member.Share(blocks);
    for (std::ptrdiff_t b = first_block; b < last_block; ++b) {
      const std::ptrdiff_t begin = b * kEdgeBlock;
      EdgeTermsBlock<kBindRadii>(in, begin, std::min(kEdgeBlock, edges - begin), term,
                                 term + edges);
    }
  });
}

Status DomainVolumeUpdater::BindEdges(const ParticleView& particles, const DomainNetwork& network) {
  std::vector<std::int32_t> edge_of_contact;  // contact id -> edge, -1 before its first walk
  const auto bind_loops = [&](std::span<const std::int32_t> offsets,
                              std::span<const std::int32_t> loop,
                              std::span<const std::int32_t> contacts, const char* field,
                              std::vector<std::int32_t>* entry_term) -> Status {
    entry_term->assign(loop.size(), -1);
    for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
      const auto begin = static_cast<std::size_t>(offsets[f]);
      const auto end = static_cast<std::size_t>(offsets[f + 1]);
      for (std::size_t q = begin; q < end; ++q) {
        const std::size_t q1 = q + 1 < end ? q + 1 : begin;
        const std::int32_t a = loop[q], b = loop[q1];
        const std::int32_t lo = std::min(a, b), hi = std::max(a, b);
        const std::int32_t c = contacts[q];
        if (c < 0) {
          return InvalidArgument(std::string("coupling.domain_volume.network.") + field + "[" +
                                 std::to_string(q) + "]: contact id " + std::to_string(c) +
                                 " is negative");
        }
        const auto cu = static_cast<std::size_t>(c);
        if (cu >= edge_of_contact.size()) edge_of_contact.resize(cu + 1, -1);
        std::int32_t& edge = edge_of_contact[cu];
        if (edge < 0) {
          edge = static_cast<std::int32_t>(edge_lo_.size());
          edge_lo_.push_back(lo);
          edge_hi_.push_back(hi);
          edge_x0_.push_back(particles.x[static_cast<std::size_t>(hi)] -
                             particles.x[static_cast<std::size_t>(lo)]);
          edge_y0_.push_back(particles.y[static_cast<std::size_t>(hi)] -
                             particles.y[static_cast<std::size_t>(lo)]);
        } else if (edge_lo_[static_cast<std::size_t>(edge)] != lo ||
                   edge_hi_[static_cast<std::size_t>(edge)] != hi) {
          return InvalidArgument(std::string("coupling.domain_volume.network.") + field + "[" +
                                 std::to_string(q) + "]: contact " + std::to_string(c) +
                                 " joins other particles elsewhere in the loops");
        }
        (*entry_term)[q] = 2 * edge + (a < b ? 0 : 1);  // made e or E + e below
      }
    }
    return Status::Ok();
  };
  edge_lo_.clear();
  edge_hi_.clear();
  edge_x0_.clear();
  edge_y0_.clear();
  SEEP_RETURN_IF_ERROR(bind_loops(network.loop_offsets, network.loop_particles,
                                  network.loop_contacts, "loop_contacts", &loop_entry_term_));
  SEEP_RETURN_IF_ERROR(bind_loops(network.outer_offsets, network.outer_particles,
                                  network.outer_contacts, "outer_contacts", &outer_entry_term_));
  // Grown by push_back: cut to their size, which they keep until the next Bind.
  edge_lo_.shrink_to_fit();
  edge_hi_.shrink_to_fit();
  edge_x0_.shrink_to_fit();
  edge_y0_.shrink_to_fit();
  const std::size_t edges = edge_lo_.size();
  // The terms of the walks lo -> hi first, then those of the walks hi -> lo: the edge pass
  // stores each as a vector, where interleaved pairs took shuffles.
  for (std::vector<std::int32_t>* entries : {&loop_entry_term_, &outer_entry_term_}) {
    for (std::int32_t& t : *entries) t = (t & 1) ? NumEdges() + t / 2 : t / 2;
  }
  edge_term_.assign(2 * edges, 0.0);
  edge_inv_r_lo_.resize(edges);
  edge_inv_r_hi_.resize(edges);
  for (std::size_t e = 0; e < edges; ++e) {
    edge_inv_r_lo_[e] = 1.0 / particles.radius[static_cast<std::size_t>(edge_lo_[e])];
    edge_inv_r_hi_[e] = 1.0 / particles.radius[static_cast<std::size_t>(edge_hi_[e])];
  }
  bind_radius_.assign(particles.radius.begin(), particles.radius.end());
  SectorsAtBind(network.loop_offsets, network.loop_particles, loop_entry_term_, NumEdges(),
                edge_x0_.data(), edge_y0_.data(), particles.radius.data(), &bind_loop_sector_);
  SectorsAtBind(network.outer_offsets, network.outer_particles, outer_entry_term_, NumEdges(),
                edge_x0_.data(), edge_y0_.data(), particles.radius.data(), &bind_outer_sector_);
  return Status::Ok();
}

Status DomainVolumeUpdater::Bind(const ParticleView& particles, const DomainNetwork& network) {
  const std::size_t num_domains = network.num_domains();
  if (network.pore_volume.size() != num_domains) {
    return InvalidArgument("coupling.domain_volume.network.pore_volume: has " +
                           std::to_string(network.pore_volume.size()) + " entries, expected " +
                           std::to_string(num_domains));
  }
  bound_particles_ = 0;
  rattler_correction_.clear();
  SEEP_RETURN_IF_ERROR(Check(particles, network, num_domains));
  SEEP_RETURN_IF_ERROR(
      CheckVolumeNetworkIds(network.loop_particles, particles.size(), "loop_particles"));
  SEEP_RETURN_IF_ERROR(
      CheckVolumeNetworkIds(network.outer_particles, particles.size(), "outer_particles"));
  if (network.loop_contacts.size() != network.loop_particles.size() ||
      network.outer_contacts.size() != network.outer_particles.size()) {
    return InvalidArgument(
        "coupling.domain_volume.network: loop contacts do not match the loop particles");
  }
  SEEP_RETURN_IF_ERROR(BindEdges(particles, network));
  bound_particles_ = particles.size();
  std::vector<double> apparent(num_domains);
  rattler_correction_.assign(num_domains, 0.0);
  // At the bind positions every turn is 0: the wedge angles are the atan2 values themselves.
  const SectorSums sectors = Sectors(particles, network);
  ComputeEdgeTerms(particles, sectors.bind_radii);
  ComputeGeometric<true>(particles, network, sectors, apparent, rattler_correction_);
  for (std::size_t d = 0; d < num_domains; ++d) {
    rattler_correction_[d] = network.pore_volume[d] - rattler_correction_[d];
  }
  return Status::Ok();
}

Status DomainVolumeUpdater::CheckBound(const DomainNetwork& network) const {
  if (network.num_domains() == rattler_correction_.size() &&
      network.loop_particles.size() == loop_entry_term_.size() &&
      network.outer_particles.size() == outer_entry_term_.size()) {
    return Status::Ok();
  }
  return FailedPrecondition(
      "coupling.domain_volume: the network has " + std::to_string(network.num_domains()) +
      " domains but the updater was bound to one with " +
      std::to_string(rattler_correction_.size()) + " (call Bind after every detection)");
}

Status DomainVolumeUpdater::Compute(const ParticleView& particles, const DomainNetwork& network,
                                    std::span<double> apparent_volume,
                                    std::span<double> pore_volume) const {
  SEEP_RETURN_IF_ERROR(CheckBound(network));
  if (pore_volume.size() != apparent_volume.size()) {
    return InvalidArgument(
        "coupling.domain_volume: apparent_volume and pore_volume differ in size");
  }
  SEEP_RETURN_IF_ERROR(Check(particles, network, apparent_volume.size()));
  const SectorSums sectors = Sectors(particles, network);
  ComputeEdgeTerms(particles, sectors.bind_radii);
  ComputeGeometric<true>(particles, network, sectors, apparent_volume, pore_volume);
  const auto domains = static_cast<std::ptrdiff_t>(pore_volume.size());
  double* pore = pore_volume.data();
  const double* correction = rattler_correction_.data();
  internal::ForEachShare(domains, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
#pragma omp simd
    for (std::ptrdiff_t d = begin; d < end; ++d) pore[d] += correction[d];
  });
  return Status::Ok();
}

Status DomainVolumeUpdater::ComputeApparent(const ParticleView& particles,
                                            const DomainNetwork& network,
                                            std::span<double> apparent_volume) const {
  SEEP_RETURN_IF_ERROR(CheckBound(network));
  SEEP_RETURN_IF_ERROR(Check(particles, network, apparent_volume.size()));
  ComputeGeometric<false>(particles, network, SectorSums{}, apparent_volume, {});
  return Status::Ok();
}

Status ComputeVolumeChange(std::span<const double> before, std::span<const double> after,
                           std::span<double> change) {
  if (after.size() != before.size() || change.size() != before.size()) {
    return InvalidArgument(
        "coupling.domain_volume.change: before, after and change differ in size (" +
        std::to_string(before.size()) + ", " + std::to_string(after.size()) + ", " +
        std::to_string(change.size()) + ")");
  }
  for (std::size_t d = 0; d < before.size(); ++d) change[d] = after[d] - before[d];
  return Status::Ok();
}

}  // namespace seep::core
