// Pressure -> particle forces by the chord rule (physics.md §2.5).
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
// Cost: one square root per loop entry, O(total loop length), no allocation. Forces are added in
// a fixed order (domains by id, then outer faces, each loop in its stored order), single
// threaded, so the result is bit-identical for a given input.
#pragma once

#include <cstdint>
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
// Errors (InvalidArgument, nothing added): array sizes, loop particle ids out of range.
Status AddPressureForces(const ParticleView& particles, const DomainNetwork& network,
                         std::span<const double> domain_pressure,
                         std::span<const double> outer_arc_pressure, std::span<double> fx,
                         std::span<double> fy);

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
