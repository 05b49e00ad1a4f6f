// Chord-rule pressure forces on the particles bounding each face, and the outside pressures of
// the outer walks (see pressure_forces.h for the rule and its consequences).
#include "seep/core/coupling/pressure_forces.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "../parallel_threshold.h"
#include "seep/core/coupling/contact_point.h"

namespace seep::core {
namespace {

std::string SizeMessage(const char* field, std::size_t got, std::size_t expected, const char* per) {
  return std::string("coupling.pressure_forces.") + field + ": has " + std::to_string(got) +
         " entries, expected " + std::to_string(expected) + " (one per " + per + ")";
}

Status CheckForceNetworkIds(std::span<const std::int32_t> ids, std::size_t n, const char* field) {
  // One pass over the loops before anything is written, so a bad network adds nothing.
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] < 0 || static_cast<std::size_t>(ids[k]) >= n) {
      return InvalidArgument(std::string("coupling.pressure_forces.network.") + field + "[" +
                             std::to_string(k) + "]: particle id " + std::to_string(ids[k]) +
                             " is not in [0, " + std::to_string(n) + ")");
    }
  }
  return Status::Ok();
}

// One walk of a face along a loop contact: u -> v, with the slots of u's and v's arcs.
struct Traversal {
  std::int32_t contact, u, v, slot_u, slot_v;
};

// The walks of the loops in CSR form [offsets, particles, contacts); `arc_slot(q)` gives the slot
// of the arc at entry q.
template <typename ArcSlot>
void AppendTraversals(std::span<const std::int32_t> offsets, std::span<const std::int32_t> loop,
                      std::span<const std::int32_t> contacts, ArcSlot arc_slot,
                      std::vector<Traversal>* out) {
  for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
    const auto begin = static_cast<std::size_t>(offsets[f]);
    const auto end = static_cast<std::size_t>(offsets[f + 1]);
    for (std::size_t q = begin; q < end; ++q) {
      const std::size_t next = q + 1 < end ? q + 1 : begin;
      out->push_back(
          Traversal{contacts[q], loop[q], loop[next], arc_slot(f, q), arc_slot(f, next)});
    }
  }
}

// A loop contact is an index into the contacts (and wall edges after them): never negative.
Status CheckContactIds(std::span<const std::int32_t> contacts, const char* field) {
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    if (contacts[k] < 0) {
      return InvalidArgument(std::string("coupling.pressure_forces.network.") + field + "[" +
                             std::to_string(k) + "]: contact id " + std::to_string(contacts[k]) +
                             " is negative");
    }
  }
  return Status::Ok();
}

// Orders the walks by contact (ids >= 0, CheckContactIds), and per contact the lo -> hi walk
// before the hi -> lo one: a counting sort on the contact id (the ids are dense), two stable
// passes, in O(walks); a comparison sort was most of a re-bind.
void SortByContact(std::vector<Traversal>* walks) {
  std::size_t buckets = 0;
  for (const Traversal& w : *walks) {
    buckets = std::max(buckets, static_cast<std::size_t>(w.contact) + 1);
  }
  std::vector<std::int32_t> first(buckets + 1, 0);
  for (const Traversal& w : *walks) ++first[static_cast<std::size_t>(w.contact) + 1];
  for (std::size_t c = 0; c < buckets; ++c) first[c + 1] += first[c];
  std::vector<Traversal> sorted(walks->size());
  // Forward walks first, so that each contact's comes before its backward one.
  for (const bool forward : {true, false}) {
    for (const Traversal& w : *walks) {
      if ((w.u < w.v) != forward) continue;
      sorted[static_cast<std::size_t>(first[static_cast<std::size_t>(w.contact)]++)] = w;
    }
  }
  *walks = std::move(sorted);
}

}  // namespace

Status AddPressureForces(const ParticleView& particles, const DomainNetwork& network,
                         std::span<const double> domain_pressure,
                         std::span<const double> outer_arc_pressure, std::span<double> fx,
                         std::span<double> fy) {
  SEEP_RETURN_IF_ERROR(CheckParticleView(particles, "coupling.pressure_forces.particles"));
  const std::size_t n = particles.size();
  const std::size_t num_domains = network.num_domains();
  if (fx.size() != n) return InvalidArgument(SizeMessage("fx", fx.size(), n, "particle"));
  if (fy.size() != n) return InvalidArgument(SizeMessage("fy", fy.size(), n, "particle"));
  if (domain_pressure.size() != num_domains) {
    return InvalidArgument(
        SizeMessage("domain_pressure", domain_pressure.size(), num_domains, "domain"));
  }
  if (!outer_arc_pressure.empty() && outer_arc_pressure.size() != network.outer_particles.size()) {
    return InvalidArgument(SizeMessage("outer_arc_pressure", outer_arc_pressure.size(),
                                       network.outer_particles.size(), "outer-loop entry"));
  }
  PressureForceKernel kernel;
  SEEP_RETURN_IF_ERROR(kernel.Bind(network, n));
  std::vector<double> slots(kernel.num_slots(), 0.0);
  std::copy(domain_pressure.begin(), domain_pressure.end(), slots.begin());
  std::copy(outer_arc_pressure.begin(), outer_arc_pressure.end(),
            slots.begin() + static_cast<std::ptrdiff_t>(num_domains));
  kernel.Apply(particles, slots.data(), fx.data(), fy.data());
  return Status::Ok();
}

Status PressureForceKernel::Bind(const DomainNetwork& network, std::size_t num_particles) {
  const std::size_t num_domains = network.num_domains();
  if (network.loop_offsets.size() != num_domains + 1 ||
      static_cast<std::size_t>(network.loop_offsets.back()) != network.loop_particles.size() ||
      network.outer_offsets.size() != network.num_outer_faces() + 1 ||
      static_cast<std::size_t>(network.outer_offsets.back()) != network.outer_particles.size()) {
    return InvalidArgument(
        "coupling.pressure_forces.network: loop offsets do not match the loop arrays");
  }
  if (network.loop_contacts.size() != network.loop_particles.size() ||
      network.outer_contacts.size() != network.outer_particles.size()) {
    return InvalidArgument(
        "coupling.pressure_forces.network: loop contacts do not match the loop particles");
  }
  SEEP_RETURN_IF_ERROR(
      CheckForceNetworkIds(network.loop_particles, num_particles, "loop_particles"));
  SEEP_RETURN_IF_ERROR(
      CheckForceNetworkIds(network.outer_particles, num_particles, "outer_particles"));
  SEEP_RETURN_IF_ERROR(CheckContactIds(network.loop_contacts, "loop_contacts"));
  SEEP_RETURN_IF_ERROR(CheckContactIds(network.outer_contacts, "outer_contacts"));
  std::vector<Traversal> walks;
  walks.reserve(network.loop_particles.size() + network.outer_particles.size());
  AppendTraversals(
      network.loop_offsets, network.loop_particles, network.loop_contacts,
      [](std::size_t face, std::size_t) { return static_cast<std::int32_t>(face); }, &walks);
  AppendTraversals(
      network.outer_offsets, network.outer_particles, network.outer_contacts,
      [num_domains](std::size_t, std::size_t q) {
        return static_cast<std::int32_t>(num_domains + q);
      },
      &walks);
  SortByContact(&walks);
  // Built aside and committed at the end: a failed Bind leaves the kernel as it was.
  std::vector<ContactTerms> terms;
  terms.reserve(walks.size() / 2);
  for (std::size_t k = 0; k < walks.size();) {
    const Traversal& fwd = walks[k];
    const bool paired = k + 1 < walks.size() && walks[k + 1].contact == fwd.contact &&
                        fwd.u < fwd.v && walks[k + 1].u == fwd.v && walks[k + 1].v == fwd.u &&
                        (k + 2 >= walks.size() || walks[k + 2].contact != fwd.contact);
    if (!paired) {
      return Internal("coupling.pressure_forces.network: contact " + std::to_string(fwd.contact) +
                      " is not walked exactly once in each direction by the face loops");
    }
    const Traversal& bwd = walks[k + 1];
    terms.push_back(ContactTerms{fwd.u, fwd.v, fwd.slot_u, bwd.slot_v, bwd.slot_u, fwd.slot_v});
    k += 2;
  }
  terms_ = std::move(terms);
  num_slots_ = num_domains + network.outer_particles.size();
  num_ids_ = num_particles;
  // The threaded path's sides are made again, for these contacts, by its first Apply.
  sides_built_ = false;
  side_start_.clear();
  side_items_.clear();
  side_fx_.clear();
  side_fy_.clear();
  return Status::Ok();
}

void PressureForceKernel::BuildSides() const {
  side_start_.assign(num_ids_ + 1, 0);
  for (const ContactTerms& t : terms_) {
    ++side_start_[static_cast<std::size_t>(t.lo) + 1];
    ++side_start_[static_cast<std::size_t>(t.hi) + 1];
  }
  for (std::size_t i = 0; i < num_ids_; ++i) side_start_[i + 1] += side_start_[i];
  side_items_.resize(2 * terms_.size());
  std::vector<std::int32_t> fill(side_start_.begin(), side_start_.end() - 1);
  for (std::size_t t = 0; t < terms_.size(); ++t) {
    const auto side = static_cast<std::int32_t>(2 * t);
    side_items_[static_cast<std::size_t>(fill[static_cast<std::size_t>(terms_[t].lo)]++)] = side;
    side_items_[static_cast<std::size_t>(fill[static_cast<std::size_t>(terms_[t].hi)]++)] =
        side + 1;
  }
  side_fx_.assign(2 * terms_.size(), 0.0);
  side_fy_.assign(2 * terms_.size(), 0.0);
  sides_built_ = true;
}

namespace {

// Contacts per block of Apply: a block's gathered inputs and forces (ten arrays of doubles,
// 20 kB) stay in L1 between its passes.
constexpr std::ptrdiff_t kForceBlock = 256;

// The pressure force of one contact on its lo and on its hi particle.
struct SideForces {
  double lo_x, lo_y, hi_x, hi_y;
};

// The forces of the gathered contacts [0, count) (see ForcesOfBlock), as vectors.
void ForcesOfGathered(std::ptrdiff_t count, const double* dx, const double* dy, const double* r_lo,
                      const double* r_hi, const double* dp_lo, const double* dp_hi,
                      double* __restrict lo_x, double* __restrict lo_y, double* __restrict hi_x,
                      double* __restrict hi_y) {
#pragma omp simd
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    const double f = ContactFractionNoBranch(r_lo[k], r_hi[k], dx[k] * dx[k] + dy[k] * dy[k]);
    const double arm_lo_x = f * dx[k], arm_lo_y = f * dy[k];
    const double arm_hi_x = (f - 1.0) * dx[k], arm_hi_y = (f - 1.0) * dy[k];
    lo_x[k] = dp_lo[k] * arm_lo_y;
    lo_y[k] = -dp_lo[k] * arm_lo_x;
    hi_x[k] = dp_hi[k] * arm_hi_y;
    hi_y[k] = -dp_hi[k] * arm_hi_x;
  }
}

}  // namespace

// Per contact, each side's pressure difference times R(arm), R(v) = (v_y, -v_x) (see the header),
// with the arms of ComputeContactArms (lo < hi: Bind pairs the walks so), the same operations
// per contact, so the same bits; sink(c, SideForces) takes them in ascending contact order.
// Contacts of equal radii, where ContactFraction is 0.5 exactly whatever the distance, are done
// one by one as they are read (a lattice or monodisperse packing does every contact so: any
// gather into arrays cost it more than it saved). From the first contact of unequal radii on,
// the rest of the block is gathered into contiguous arrays and its contact points and forces
// made as vectors (ContactFractionNoBranch: one square root and one division per lane, where a
// scalar loop waited on both for every contact).
template <typename Sink>
void PressureForceKernel::ForcesOfBlock(const ParticleView& particles, const double* slot_pressure,
                                        std::ptrdiff_t begin, std::ptrdiff_t count,
                                        Sink& sink) const {
  const ContactTerms* t = terms_.data() + begin;
  const double* x = particles.x.data();
  const double* y = particles.y.data();
  const double* r = particles.radius.data();
  // Each side's pressure difference: F1 - F2 on lo's arc, F2 - F1 on hi's.
  const auto lo_difference = [slot_pressure](const ContactTerms& c) {
    return slot_pressure[c.forward_lo] - slot_pressure[c.backward_lo];
  };
  const auto hi_difference = [slot_pressure](const ContactTerms& c) {
    return slot_pressure[c.backward_hi] - slot_pressure[c.forward_hi];
  };
  std::ptrdiff_t k = 0;
  for (; k < count; ++k) {
    const std::ptrdiff_t lo = t[k].lo, hi = t[k].hi;
    if (r[lo] != r[hi]) break;
    const double dx = x[hi] - x[lo], dy = y[hi] - y[lo];
    const double dp_lo = lo_difference(t[k]), dp_hi = hi_difference(t[k]);
    // f = 0.5 and f - 1 = -0.5, both exact.
    sink(begin + k, SideForces{dp_lo * (0.5 * dy), -dp_lo * (0.5 * dx), dp_hi * (-0.5 * dy),
                               -dp_hi * (-0.5 * dx)});
  }
  if (k == count) return;
  const std::ptrdiff_t first = k;
  alignas(64) double dx[kForceBlock], dy[kForceBlock], r_lo[kForceBlock], r_hi[kForceBlock];
  alignas(64) double dp_lo[kForceBlock], dp_hi[kForceBlock];
  for (; k < count; ++k) {
    const std::ptrdiff_t lo = t[k].lo, hi = t[k].hi;
    dx[k] = x[hi] - x[lo];
    dy[k] = y[hi] - y[lo];
    r_lo[k] = r[lo];
    r_hi[k] = r[hi];
    dp_lo[k] = lo_difference(t[k]);
    dp_hi[k] = hi_difference(t[k]);
  }
  alignas(64) double out_lo_x[kForceBlock], out_lo_y[kForceBlock];
  alignas(64) double out_hi_x[kForceBlock], out_hi_y[kForceBlock];
  ForcesOfGathered(count - first, dx + first, dy + first, r_lo + first, r_hi + first, dp_lo + first,
                   dp_hi + first, out_lo_x + first, out_lo_y + first, out_hi_x + first,
                   out_hi_y + first);
  for (k = first; k < count; ++k) {
    sink(begin + k, SideForces{out_lo_x[k], out_lo_y[k], out_hi_x[k], out_hi_y[k]});
  }
}

void PressureForceKernel::Apply(const ParticleView& particles, const double* slot_pressure,
                                double* fx, double* fy) const {
  Apply(particles, slot_pressure, {fx, fy});
}

void PressureForceKernel::Apply(const ParticleView& particles, const double* slot_pressure,
                                const ForceOutput& out) const {
  const ContactTerms* terms = terms_.data();
  // Wall vertices (ids from out.num_particles on) write to the vertex arrays.
  const auto first_vertex = static_cast<std::int32_t>(
      std::min<std::size_t>(out.num_particles, std::numeric_limits<std::int32_t>::max()));
  const auto add = [&](std::int32_t id, double x, double y) {
    if (id < first_vertex) {
      out.fx[id] += x;
      out.fy[id] += y;
    } else {
      out.vertex_fx[id - first_vertex] += x;
      out.vertex_fy[id - first_vertex] += y;
    }
  };
  const auto contacts = static_cast<std::ptrdiff_t>(terms_.size());
  if (!internal::OnTeam(contacts)) {
    // One thread: add each contact's forces straight away, in ascending contact order.
    auto add_both = [&](std::ptrdiff_t c, const SideForces& s) {
      add(terms[c].lo, s.lo_x, s.lo_y);
      add(terms[c].hi, s.hi_x, s.hi_y);
    };
    for (std::ptrdiff_t begin = 0; begin < contacts; begin += kForceBlock) {
      ForcesOfBlock(particles, slot_pressure, begin, std::min(kForceBlock, contacts - begin),
                    add_both);
    }
    return;
  }
  // Threads: the forces into per-side slots, then each particle adds its slots one by one in
  // ascending contact order: the same additions in the same order as above, so the same bits.
  if (!sides_built_) BuildSides();
  double* side_x = side_fx_.data();
  double* side_y = side_fy_.data();
  const std::int32_t* start = side_start_.data();
  const std::int32_t* items = side_items_.data();
  const auto n = static_cast<std::ptrdiff_t>(side_start_.size()) - 1;
  const std::ptrdiff_t blocks = (contacts + kForceBlock - 1) / kForceBlock;
  internal::RunOnTeam(internal::CoreThreads(), [&](const internal::TeamMember& member) {
    auto to_slots = [&](std::ptrdiff_t c, const SideForces& s) {
      side_x[2 * c] = s.lo_x;
      side_y[2 * c] = s.lo_y;
      side_x[2 * c + 1] = s.hi_x;
      side_y[2 * c + 1] = s.hi_y;
    };
    const auto [first_block, last_block] = member.Share(blocks);
    for (std::ptrdiff_t b = first_block; b < last_block; ++b) {
      const std::ptrdiff_t begin = b * kForceBlock;
      ForcesOfBlock(particles, slot_pressure, begin, std::min(kForceBlock, contacts - begin),
                    to_slots);
    }
    member.Barrier();  // the gather reads the other members' slots
    const auto [first, last] = member.Share(n);
    for (std::ptrdiff_t i = first; i < last; ++i) {
      const bool vertex = i >= first_vertex;
      double* px = vertex ? out.vertex_fx + (i - first_vertex) : out.fx + i;
      double* py = vertex ? out.vertex_fy + (i - first_vertex) : out.fy + i;
      double ax = *px, ay = *py;
      for (std::int32_t k = start[i]; k < start[i + 1]; ++k) {
        ax += side_x[items[k]];
        ay += side_y[items[k]];
      }
      *px = ax;
      *py = ay;
    }
  });
}

Status OuterArcPressures::Compute(const DomainNetwork& network,
                                  std::span<const double> domain_pressure,
                                  std::span<const double> boundary_pipe_pressure,
                                  std::vector<double>* arc_pressure) {
  const std::size_t num_domains = network.num_domains();
  const std::size_t num_boundary = network.num_boundary_pipes();
  if (domain_pressure.size() != num_domains) {
    return InvalidArgument(
        SizeMessage("domain_pressure", domain_pressure.size(), num_domains, "domain"));
  }
  if (boundary_pipe_pressure.size() != num_boundary) {
    return InvalidArgument(SizeMessage("boundary_pipe_pressure", boundary_pipe_pressure.size(),
                                       num_boundary, "boundary pipe"));
  }
  const std::size_t entries = network.outer_particles.size();
  if (network.outer_contacts.size() != entries ||
      network.outer_offsets.size() != network.num_outer_faces() + 1 ||
      network.outer_host_domain.size() != network.num_outer_faces()) {
    return InvalidArgument("coupling.pressure_forces.network: outer-loop arrays do not match");
  }
  // Contact -> boundary pipe lookup, sized by the largest contact id on an outer walk.
  std::int32_t max_contact = -1;
  for (const std::int32_t c : network.outer_contacts) max_contact = std::max(max_contact, c);
  for (const std::int32_t c : network.boundary_pipe_contact) max_contact = std::max(max_contact, c);
  if (network.boundary_pipe_domain.size() != num_boundary) {
    return InvalidArgument("coupling.pressure_forces.network: boundary-pipe arrays differ in size");
  }
  for (std::size_t b = 0; b < num_boundary; ++b) {
    const std::int32_t d = network.boundary_pipe_domain[b];
    if (network.boundary_pipe_contact[b] < 0 || d < 0 ||
        static_cast<std::size_t>(d) >= num_domains) {
      return InvalidArgument("coupling.pressure_forces.network.boundary_pipe[" + std::to_string(b) +
                             "]: contact or domain id out of range");
    }
  }
  const std::size_t lookup_size = static_cast<std::size_t>(max_contact + 1);
  if (boundary_pipe_of_contact_.size() < lookup_size) {
    boundary_pipe_of_contact_.resize(lookup_size, -1);
  }
  for (std::size_t b = 0; b < num_boundary; ++b) {
    boundary_pipe_of_contact_[static_cast<std::size_t>(network.boundary_pipe_contact[b])] =
        static_cast<std::int32_t>(b);
  }

  arc_pressure->resize(entries);
  double* out = arc_pressure->data();
  const std::int32_t* lookup = boundary_pipe_of_contact_.data();
  for (std::size_t k = 0; k < network.num_outer_faces(); ++k) {
    const std::size_t begin = static_cast<std::size_t>(network.outer_offsets[k]);
    const std::size_t end = static_cast<std::size_t>(network.outer_offsets[k + 1]);
    const std::int32_t host = network.outer_host_domain[k];
    if (host >= 0) {
      std::fill(out + begin, out + end, domain_pressure[static_cast<std::size_t>(host)]);
      continue;
    }
    // What the outside of each hull contact holds: a reservoir, a dead-end pocket, or nothing.
    auto contact_value = [&](std::int32_t contact, double* reservoir, double* pocket) {
      const std::int32_t b = contact >= 0 ? lookup[contact] : -1;
      if (b < 0) return 0;
      const double value = boundary_pipe_pressure[static_cast<std::size_t>(b)];
      if (std::isfinite(value)) {
        *reservoir += value;
        return 1;
      }
      *pocket += domain_pressure[static_cast<std::size_t>(network.boundary_pipe_domain[b])];
      return 2;
    };
    std::size_t first_known = end;
    for (std::size_t q = begin; q < end; ++q) {
      const std::int32_t before = network.outer_contacts[q > begin ? q - 1 : end - 1];
      const std::int32_t after = network.outer_contacts[q];
      double reservoir = 0.0, pocket = 0.0;
      int reservoirs = 0, pockets = 0;
      for (const std::int32_t c : {before, after}) {
        const int kind = contact_value(c, &reservoir, &pocket);
        reservoirs += kind == 1;
        pockets += kind == 2;
      }
      if (reservoirs > 0) {
        out[q] = reservoir / reservoirs;
      } else if (pockets > 0) {
        out[q] = pocket / pockets;
      } else {
        out[q] = std::nan("");
        continue;
      }
      if (first_known == end) first_known = q;
    }
    // Arcs between two bridges carry the value before them along the walk.
    if (first_known == end) {
      std::fill(out + begin, out + end, 0.0);
      continue;
    }
    double carried = out[first_known];
    for (std::size_t step = 1; step < end - begin; ++step) {
      std::size_t q = first_known + step;
      if (q >= end) q -= end - begin;
      if (std::isnan(out[q])) {
        out[q] = carried;
      } else {
        carried = out[q];
      }
    }
  }
  for (std::size_t b = 0; b < num_boundary; ++b) {
    boundary_pipe_of_contact_[static_cast<std::size_t>(network.boundary_pipe_contact[b])] = -1;
  }
  // The outside of a wall is not the sample's: nothing there pushes on the wall (the pressure
  // behind a drained platen holds the platen, not the sample).
  if (!network.walls.empty()) {
    for (std::size_t q = 0; q < entries; ++q) {
      if (network.walls.IsWallVertex(network.outer_particles[q])) out[q] = 0.0;
    }
  }
  return Status::Ok();
}

}  // namespace seep::core
