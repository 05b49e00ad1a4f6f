// Pressure -> particle forces by the chord rule (docs/physics.md §2.5).
//
// A face (domain or outer face) touches particle k of its loop along the arc between the contact
// points c_{k-1,k} and c_{k,k+1} (contact_point.h). The exact force of a uniform pressure P on
// that arc is
//
//   F_k = P |c_{k,k+1} - c_{k-1,k}| e_k = P (t_y, -t_x),   t = c_{k,k+1} - c_{k-1,k},
//
// with e_k the chord normal pointing away from the face. Every loop of a DomainNetwork has its
// face on the left (domains are traced counter-clockwise, outer walks clockwise), so e_k is the
// right-hand normal of t for both, and the same expression is right for minor arcs and for the
// major arc of a particle protruding into a large void (the force then points from the centre
// towards the chord, still away from the void). Why: the arc and its chord bound a circular
// segment, and the integral of the normal around a closed curve is zero. On a circle the arc
// normals are radial, so F_k passes through the centre: no torque is produced.
//
// Consequences (tests V14, V15): the chords of one face close, so sum_k F_k = 0 per face; a
// particle wetted all round at one pressure feels no net force; the net force on an assembly is
// the sum over its outer arcs of (outside pressure) x (chord length) x (inward normal).
//
// Outside pressures. The outer walk of a top-level component is wetted by the boundary fluid;
// its pressure is given per outer-loop entry q (the arc of outer_particles[q] between the
// contacts outer_contacts[q-1] and outer_contacts[q]). OuterArcPressures derives these from the
// reservoirs of the boundary pipes (see there). An island (outer loop inside a host domain) is
// wetted by its host's fluid.
//
// Per contact, not per loop entry. Each contact c = (lo, hi) of a loop is traversed by exactly
// two face walks, once lo -> hi (face F1) and once hi -> lo (face F2). In a walk u -> v the arm of
// u at c is u's "next" arm (+P) and the arm of v is v's "previous" arm (-P), so summing the chord
// rule over the faces gives, with d = x_hi - x_lo, f the contact fraction (contact_point.h) and
// R(v) = (v_y, -v_x):
//   F_lo += (P_F1(lo) - P_F2(lo)) f R(d),   F_hi += (P_F2(hi) - P_F1(hi)) (f - 1) R(d),
// where P_F(k) is the pressure face F applies on particle k's arc (the domain's, or the outer
// arc's). One contact fraction and four pressure reads per contact replace two arm computations
// per loop entry, and a uniform pressure cancels exactly, contact by contact (V14 to the bit).
//
// Cost: O(contacts on loops) per call, no allocation after Bind. One thread adds each contact's
// two contributions to its particles in ascending contact order; several threads write them to
// per-contact slots and then each particle adds its slots one by one in that same order (a team
// run over contacts, then over particles): the same additions in the same order, so the result is
// bit-identical for a given input on any thread count.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "seep/core/coupling/particle_view.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/status.h"

namespace seep::core {

// Adds the pressure forces (N per m of thickness for Pa and m) to fx, fy (size = particle count).
//   domain_pressure     one per domain of `network`, Pa;
//   outer_arc_pressure  one per entry of network.outer_particles, Pa, or empty: no outside fluid
//                       (zero gauge pressure outside every outer walk, islands included).
// Errors (nothing added): InvalidArgument for array sizes and loop particle ids out of range;
// Internal for loops that do not walk every contact once in each direction (see Bind).
Status AddPressureForces(const ParticleView& particles, const DomainNetwork& network,
                         std::span<const double> domain_pressure,
                         std::span<const double> outer_arc_pressure, std::span<double> fx,
                         std::span<double> fy);

// The chord rule bound to one network: Bind() pairs up the two face walks of every loop contact
// (O(loop length log), allocates); Apply() is the per-step pass. Pressures are read from one
// "slot" array: slots [0, num_domains) are the domain pressures, slot num_domains + q the
// pressure on outer-loop arc q (AddPressureForces' outer_arc_pressure).
class PressureForceKernel {
 public:
  // Internal error if some loop contact is not walked exactly once in each direction (a network
  // not produced by the DomainDetector); particle ids are checked against num_particles.
  Status Bind(const DomainNetwork& network, std::size_t num_particles);
  // Adds the forces for the bound network; slot_pressure has num_slots() entries, fx and fy one
  // per particle (sizes are the caller's duty: this is the hot path). Uses the kernel's scratch:
  // one kernel per calling thread. On threads, the first call after a Bind allocates it.
  void Apply(const ParticleView& particles, const double* slot_pressure, double* fx,
             double* fy) const;
  // Where the forces go when the loops name wall vertices (domain_walls.h): ids below
  // num_particles into fx, fy; ids from num_particles on into vertex_fx, vertex_fy (indexed by
  // id - num_particles). `particles` then views the particles followed by the wall vertices, and
  // Bind took their total count.
  struct ForceOutput {
    double* fx = nullptr;
    double* fy = nullptr;
    std::size_t num_particles = std::numeric_limits<std::size_t>::max();
    double* vertex_fx = nullptr;
    double* vertex_fy = nullptr;
  };
  void Apply(const ParticleView& particles, const double* slot_pressure,
             const ForceOutput& out) const;
  std::size_t num_slots() const { return num_slots_; }
  std::size_t num_contacts() const { return terms_.size(); }

 private:
  struct ContactTerms {
    std::int32_t lo, hi;
    std::int32_t forward_lo, backward_lo;  // slots: F1 on lo's arc, F2 on lo's arc
    std::int32_t backward_hi, forward_hi;  // slots: F2 on hi's arc, F1 on hi's arc
  };
  // The threaded path's per-particle lists and slots for the bound contacts.
  void BuildSides() const;
  // The forces of contacts [begin, begin + count), count at most a block, handed to sink in
  // contact order (defined and used in the .cc).
  template <typename Sink>
  void ForcesOfBlock(const ParticleView& particles, const double* slot_pressure,
                     std::ptrdiff_t begin, std::ptrdiff_t count, Sink& sink) const;

  std::vector<ContactTerms> terms_;
  std::size_t num_slots_ = 0;
  std::size_t num_ids_ = 0;  // particles (and wall vertices) Bind took
  // What only the threaded path uses, made by its first Apply after a Bind: a run on one thread
  // never holds them (40 bytes a contact and 4 a particle).
  mutable bool sides_built_ = false;
  // Per particle, its contact sides (2 x contact + 0 for lo, 1 for hi) in ascending order (CSR).
  mutable std::vector<std::int32_t> side_start_, side_items_;
  // The force on each contact side.
  mutable std::vector<double> side_fx_, side_fy_;
};

// Outside pressure of every outer-loop arc from the boundary conditions of the flow problem.
//
// boundary_pipe_pressure has one entry per boundary pipe of the network: the pressure of the
// reservoir that pipe drains into, or NaN for an impermeable hull contact (a no-flow side). An
// arc of a top-level outer walk lies between two hull contacts and takes:
//   - the reservoir pressure if one of them drains into a reservoir (the mean of the two if both
//     do), so a corner particle between an inlet face and a no-flow side is wetted by the inlet
//     fluid all round its outer arc; this makes the net force on a permeameter sample exactly
//     (p_in - p_out) times the span of the end faces' chords;
//   - otherwise the pressure of the fluid pocket beyond its impermeable hull contacts: a pocket
//     closed by a wall is a dead end of the domain beside the contact, so at equilibrium it
//     holds that domain's pressure (the mean over the arc's two contacts);
//   - otherwise (both contacts are bridges, with the outside on both sides) the value of the
//     arc before it along the walk, or 0 if no arc of the walk has a value.
// Island outer walks take their host domain's pressure. Allocates only when a buffer grows.
class OuterArcPressures {
 public:
  Status Compute(const DomainNetwork& network, std::span<const double> domain_pressure,
                 std::span<const double> boundary_pipe_pressure, std::vector<double>* arc_pressure);

 private:
  std::vector<std::int32_t> boundary_pipe_of_contact_;  // -1 except while Compute runs
};

}  // namespace seep::core
