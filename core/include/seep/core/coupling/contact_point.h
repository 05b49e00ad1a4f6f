// Where two disks of a loop meet: the contact point on their line of centres (docs/physics.md
// §2.5).
//
//   gap >= 0 (touching or apart): halfway across the gap, r_a + g/2 from centre a;
//   overlap (gap < 0):            on the radical line (the common chord of the two circles).
// Both rules give r_a at g = 0, so the point moves continuously through first contact.
//
// The point is returned as two "arms", the vectors from each centre to it. Working relative to
// the centres keeps the chords of a particle exact to round-off of R rather than of the absolute
// coordinates, and the arms are computed from the pair in ascending id order so that the two
// faces on either side of a contact get bit-identical values: the chords around a particle then
// telescope, which is what makes a uniform pressure give zero net force (V14).
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include "seep/core/coupling/particle_view.h"

namespace seep::core {

struct ContactArms {
  double ax = 0.0, ay = 0.0;  // centre of a -> contact point
  double bx = 0.0, by = 0.0;  // centre of b -> contact point
};

// c ? a : b on the bits, so that it compiles to a mask and no branch: GCC turns a ternary of
// doubles into a jump, and sinks the operand only one side needs (a square root) behind it.
inline double SelectBits(bool c, double a, double b) {
  const std::uint64_t mask = 0 - static_cast<std::uint64_t>(c);
  return std::bit_cast<double>((std::bit_cast<std::uint64_t>(a) & mask) |
                               (std::bit_cast<std::uint64_t>(b) & ~mask));
}

// The contact fraction by the rule of the pair's state, for d2 > 0: overlap, the radical line,
// 0.5 + (r_lo^2 - r_hi^2) / (2 d2); a gap, mid-gap, 0.5 + (r_lo - r_hi) / (2 d). Both operands
// selected, one division: whether a loop contact overlaps or holds a gap changes from contact to
// contact in a settled packing, and a branch on it was mispredicted about every other contact
// (the same bits either way); the selects on the bits also vectorise.
inline double ContactFractionOfEitherRule(double r_lo, double r_hi, double d2) {
  const double sum = r_lo + r_hi;
  const bool overlap = d2 < sum * sum;
  const double distance = std::sqrt(d2);
  const double numerator = SelectBits(overlap, r_lo * r_lo - r_hi * r_hi, r_lo - r_hi);
  const double denominator = 2.0 * SelectBits(overlap, d2, distance);
  double f = 0.5 + numerator / denominator;
  // Deep overlaps can put the radical line beyond a centre; the point stays on the segment
  // (std::clamp(f, 0, 1) written out: a branch rarely taken).
  f = f < 0.0 ? 0.0 : f;
  return 1.0 < f ? 1.0 : f;
}

// Fraction of the way from centre lo to centre hi at which the contact point lies, in [0, 1].
// d2 = squared centre distance (0 gives 1/2: coincident centres have zero-length arms anyway).
inline double ContactFraction(double r_lo, double r_hi, double d2) {
  if (!(d2 > 0.0)) return 0.5;
  // Equal radii (lattices, monodisperse DEM): both rules give 0.5 + (+0)/(...) = 0.5 exactly, so
  // the division, most of the work per contact there, is skipped. A branch that goes one way for
  // a whole monodisperse or polydisperse packing.
  if (r_lo == r_hi) return 0.5;
  return ContactFractionOfEitherRule(r_lo, r_hi, d2);
}

// ContactFraction without a branch, for `omp simd` loops: a vector of contacts takes one square
// root and one division per lane. The same bits: with equal radii the rule gives
// 0.5 + (+0) / (positive) = 0.5, and coincident centres (d2 = 0, a division by zero there)
// select 0.5 after the fact.
inline double ContactFractionNoBranch(double r_lo, double r_hi, double d2) {
  const double f = ContactFractionOfEitherRule(r_lo, r_hi, d2);
  return d2 > 0.0 ? f : 0.5;
}

// Arms of particles a and b (ids into `p`, unchecked).
inline ContactArms ComputeContactArms(const ParticleView& p, std::int32_t a, std::int32_t b) {
  const bool a_is_lo = a < b;
  const std::size_t lo = static_cast<std::size_t>(a_is_lo ? a : b);
  const std::size_t hi = static_cast<std::size_t>(a_is_lo ? b : a);
  const double dx = p.x[hi] - p.x[lo];
  const double dy = p.y[hi] - p.y[lo];
  const double f = ContactFraction(p.radius[lo], p.radius[hi], dx * dx + dy * dy);
  const double lo_x = f * dx, lo_y = f * dy;
  const double hi_x = (f - 1.0) * dx, hi_y = (f - 1.0) * dy;
  return a_is_lo ? ContactArms{lo_x, lo_y, hi_x, hi_y} : ContactArms{hi_x, hi_y, lo_x, lo_y};
}

}  // namespace seep::core
