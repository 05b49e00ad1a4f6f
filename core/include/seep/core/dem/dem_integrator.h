// Body forces, PFC local damping, the velocity-Verlet integrator and the stable step estimate.
//
// Integrator: velocity-Verlet (kick-drift-kick), the scheme of the shared benchmark and of
// LAMMPS fix nve/sphere, so our figures compare like with like:
//   FirstHalf:  v += (dt/2) F/m,  omega += (dt/2) T/I,  x += dt v     (F, T of the last pass)
//   (forces are computed at the new positions, with the half-step velocities)
//   SecondHalf: v += (dt/2) F/m,  omega += (dt/2) T/I
// Positions are the same as PFC's central-difference (leapfrog) scheme; velocity-Verlet also
// gives velocities at whole steps (kinetic energy, restitution), which is why it was chosen.
// Both are second order and stable for dt < 2 / omega_max.
// `fixed` particles keep v and omega (their x still advances with the held velocity).
#pragma once

#include "seep/core/dem/contact_law.h"
#include "seep/core/dem/dem_counters.h"
#include "seep/core/dem/dem_particles.h"
#include "seep/core/dem/parallel_bond.h"
#include "seep/core/status.h"

namespace seep::core {

// F += m g for every particle (fixed ones too: their velocity is held anyway, and their force
// then reads as the support reaction).
void AddGravity(DemParticles* particles, double gx, double gy, DemCounters* counters);

// PFC local damping: each force component (and the torque) becomes
//   F_k - alpha |F_k| sign(v_k)
// (alpha in [0, 1), typically 0.7 for quasi-static loading). Call after all forces are summed.
// sign(v) = 0 at rest, and a velocity below kRestFraction of the one the force gives in a step
// (|F| dt / m) is rest: a component that is 0 in exact arithmetic (a particle at rest along a
// direction no force acts on, a symmetric lattice) carries rounding instead, and its sign put
// alpha |F| one way or the other as the rounding fell, so a translated or turned sample took
// another path (the metamorphic suite's translation law found it). 1e-9 is far above rounding
// (1e-16 of the velocities the forces give) and far below any velocity of the motion: a real
// velocity lands within it of zero about once in 1e9 reversals.
inline constexpr double kRestFraction = 1e-9;
void ApplyLocalDamping(DemParticles* particles, double alpha, double dt, DemCounters* counters);

void IntegrateFirstHalf(DemParticles* particles, double dt, DemCounters* counters);
void IntegrateSecondHalf(DemParticles* particles, double dt, DemCounters* counters);

// A stable step for the linear contact law:
//   dt = safety * min_i min( sqrt(m_i / kn), sqrt(I_i / (kt R_i^2)) )
// sqrt(m/k) is 1/omega of one disk on one spring (translation), sqrt(I/(kt R^2)) the same for
// rotation through the tangential spring; velocity-Verlet is stable up to dt = 2/omega, and a
// disk held by several contacts has a stiffer effective spring (about coordination x kn), so use
// safety <= 1 (0.1-0.3 is usual). kt = 0 drops the rotational term. safety in (0, 2].
//
// With parallel bonds (`bonds` not null) every spring of a disk of radius R may also be a bond of
// area A = 2 lambda R (per unit thickness; the bond uses the smaller radius, so R bounds it):
//   translation kn + kn_b A,
//   rotation    (kt + ks_b A) R^2 + kn_b A^3 / 12   (the bond's bending stiffness kn_b I)
// in place of kn and kt R^2. A bond is stiffer than the contact beside it (twice kn in the
// hydrofrac scene), and a step set by the contact alone let bonds break within ten steps of an
// unloaded sample at safety 0.5.
Result<double> EstimateStableTimeStep(const DemParticles& particles, double kn, double kt,
                                      double safety, const BondParams* bonds = nullptr);

}  // namespace seep::core
