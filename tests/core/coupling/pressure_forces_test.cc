// V14 (pressure forces, docs/physics.md §5), the major-arc case of the chord rule (§2.5) and the
// bound per-contact kernel.
#include "seep/core/coupling/pressure_forces.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "coupling_test_util.h"
#include "seep/core/coupling/contact_point.h"

namespace seep::core {
namespace {

using coupling_test::Detect;
using coupling_test::Detected;

struct Forces {
  std::vector<double> fx, fy;
};

Forces UniformForces(const Detected& d, double pressure, bool with_outside) {
  Forces f{std::vector<double>(d.packing.size(), 0.0), std::vector<double>(d.packing.size(), 0.0)};
  const std::vector<double> domain_pressure(d.domains.num_domains(), pressure);
  std::vector<double> arcs;
  if (with_outside) {
    const std::vector<double> reservoir(d.domains.num_boundary_pipes(), pressure);
    OuterArcPressures outer;
    EXPECT_TRUE(outer.Compute(d.domains, domain_pressure, reservoir, &arcs).ok());
  }
  const Status s =
      AddPressureForces(ViewOf(d.packing), d.domains, domain_pressure, arcs, f.fx, f.fy);
  EXPECT_TRUE(s.ok()) << s.ToString();
  return f;
}

// Particles that bound at least one face (domain or outer walk); rattlers bound none.
std::vector<char> OnSomeLoop(const Detected& d) {
  std::vector<char> on(d.packing.size(), 0);
  for (const std::int32_t p : d.domains.loop_particles) on[static_cast<std::size_t>(p)] = 1;
  for (const std::int32_t p : d.domains.outer_particles) on[static_cast<std::size_t>(p)] = 1;
  return on;
}

std::vector<char> OnOuterLoop(const Detected& d) {
  std::vector<char> on(d.packing.size(), 0);
  for (const std::int32_t p : d.domains.outer_particles) on[static_cast<std::size_t>(p)] = 1;
  return on;
}

// V14 on one packing. docs/physics.md §5's tolerance is 1e-12 P R; the kernel sums the chord rule
// per contact, as (pressure on one side - pressure on the other) x arm, so a uniform pressure gives
// exactly 0 on every wetted particle: the test asserts the bit, not the tolerance.
void ExpectUniformPressureBalances(const Detected& d, const char* name,
                                   std::size_t min_domains = 10) {
  SCOPED_TRACE(name);
  constexpr double kPressure = 3.7e6;
  double r_max = 0.0;
  for (double r : d.packing.radius) r_max = std::max(r_max, r);
  const double scale = kPressure * r_max;
  ASSERT_GE(d.domains.num_domains(), min_domains);

  // Domains only: every particle not on an outer walk is surrounded by domains.
  const Forces inner = UniformForces(d, kPressure, /*with_outside=*/false);
  const std::vector<char> outer = OnOuterLoop(d);
  std::size_t surrounded = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < d.packing.size(); ++i) {
    if (outer[i]) continue;
    ++surrounded;
    worst = std::max(worst, std::hypot(inner.fx[i], inner.fy[i]) / scale);
  }
  if (min_domains >= 10) {
    EXPECT_GT(surrounded, 10u);
  }
  EXPECT_EQ(worst, 0.0) << "largest |F| / (P R) on a particle surrounded by domains";

  // With the same pressure outside, every particle is wetted all round.
  const Forces all = UniformForces(d, kPressure, /*with_outside=*/true);
  const std::vector<char> on_loop = OnSomeLoop(d);
  double worst_all = 0.0;
  double sum_x = 0.0, sum_y = 0.0;
  for (std::size_t i = 0; i < d.packing.size(); ++i) {
    if (!on_loop[i]) {
      EXPECT_EQ(all.fx[i], 0.0);  // rattlers bound no face
      EXPECT_EQ(all.fy[i], 0.0);
    }
    worst_all = std::max(worst_all, std::hypot(all.fx[i], all.fy[i]) / scale);
    sum_x += all.fx[i];
    sum_y += all.fy[i];
  }
  EXPECT_EQ(worst_all, 0.0) << "largest |F| / (P R) with the outside at the same pressure";
  // The boundary integral of a uniform pressure over a closed boundary is zero.
  EXPECT_LT(std::hypot(sum_x, sum_y) / scale, 1e-12 * static_cast<double>(d.packing.size()));

  // Per domain, sum_k F_k = 0: the chords of one loop close. The sum is over ~4-8 chords of
  // length ~R, so its round-off is ~1e-15 P R.
  const std::size_t n = d.packing.size();
  std::vector<double> fx(n), fy(n);
  std::vector<double> one(d.domains.num_domains(), 0.0);
  double worst_domain = 0.0;
  for (std::size_t k = 0; k < d.domains.num_domains(); ++k) {
    std::fill(fx.begin(), fx.end(), 0.0);
    std::fill(fy.begin(), fy.end(), 0.0);
    one[k] = kPressure;
    ASSERT_TRUE(AddPressureForces(ViewOf(d.packing), d.domains, one, {}, fx, fy).ok());
    one[k] = 0.0;
    double sx = 0.0, sy = 0.0;
    for (std::int32_t q = d.domains.loop_offsets[k]; q < d.domains.loop_offsets[k + 1]; ++q) {
      const auto p =
          static_cast<std::size_t>(d.domains.loop_particles[static_cast<std::size_t>(q)]);
      sx += fx[p];
      sy += fy[p];
      fx[p] = fy[p] = 0.0;  // a particle visited twice is counted once
    }
    worst_domain = std::max(worst_domain, std::hypot(sx, sy) / scale);
  }
  EXPECT_LT(worst_domain, 1e-12) << "largest |sum_k F_k| / (P R) over one domain";
}

TEST(PressureForces, V14_UniformPressureSquareLattice) {
  const Detected d = Detect(coupling_test::Square(9, 7, 1e-3));
  ExpectUniformPressureBalances(d, "square 9x7");
}

TEST(PressureForces, V14_UniformPressureHexLattice) {
  const Detected d = Detect(coupling_test::Hex(10, 8, 1e-3));
  ExpectUniformPressureBalances(d, "hex 10x8");
}

TEST(PressureForces, V14_UniformPressureRandomPacking) {
  // Far from the origin, to show the arms keep the result independent of absolute position.
  Packing p = coupling_test::Random(7);
  for (double& x : p.x) x += 1e3;
  const Detected d = Detect(std::move(p), 1e-2);
  EXPECT_GT(d.domains.num_pruned_particles, 0) << "the case is meant to include rattlers";
  ExpectUniformPressureBalances(d, "random 300");
}

// An island (triangle inside a ring) is wetted by its host's fluid: with every pressure equal
// nothing moves, and with the host alone pressurised the island's disks are squeezed towards
// its centre (each by P times its 300-degree arc's chord, R).
TEST(PressureForces, V14_IslandIsWettedByItsHost) {
  constexpr double kR = 1.0;
  constexpr int kRing = 16;
  Packing p;
  coupling_test::AddRing(&p, kRing, kR);
  coupling_test::AddTriangle(&p, 0.0, 0.0, kR, 0.3);
  const Detected d = Detect(std::move(p));
  ASSERT_EQ(d.domains.num_domains(), 2u);
  ExpectUniformPressureBalances(d, "ring with island", /*min_domains=*/2);

  const std::size_t host = d.domains.apparent_volume[0] > d.domains.apparent_volume[1] ? 0 : 1;
  std::vector<double> pressure(2, 0.0);
  pressure[host] = 1e3;
  const std::vector<double> outside(d.domains.num_boundary_pipes(), 0.0);
  std::vector<double> arcs;
  OuterArcPressures outer;
  ASSERT_TRUE(outer.Compute(d.domains, pressure, outside, &arcs).ok());
  std::vector<double> fx(d.packing.size(), 0.0), fy(d.packing.size(), 0.0);
  ASSERT_TRUE(AddPressureForces(ViewOf(d.packing), d.domains, pressure, arcs, fx, fy).ok());
  for (std::size_t i = kRing; i < d.packing.size(); ++i) {
    const double inward = -(fx[i] * d.packing.x[i] + fy[i] * d.packing.y[i]) /
                          std::hypot(d.packing.x[i], d.packing.y[i]);
    EXPECT_NEAR(inward, 1e3 * kR, 1e-12 * 1e3 * kR) << "island disk " << i;
    EXPECT_NEAR(std::hypot(fx[i], fy[i]), 1e3 * kR, 1e-12 * 1e3 * kR) << "island disk " << i;
  }
}

// On a square lattice each particle bounds four quarter-cell domains; the chord facing domain
// (+R, +R) runs from (R, 0) to (0, R) and the force points towards the centre: -P R (1, 1).
TEST(PressureForces, SquareCellChordForce) {
  constexpr double kR = 0.5;
  const Detected d = Detect(coupling_test::Square(2, 2, kR));
  ASSERT_EQ(d.domains.num_domains(), 1u);
  std::vector<double> fx(4, 0.0), fy(4, 0.0);
  const double p[] = {10.0};
  ASSERT_TRUE(AddPressureForces(ViewOf(d.packing), d.domains, p, {}, fx, fy).ok());
  // Particle 0 is at (R, R), the cell centre at (2R, 2R): pushed towards -x, -y.
  EXPECT_NEAR(fx[0], -10.0 * kR, 1e-15);
  EXPECT_NEAR(fy[0], -10.0 * kR, 1e-15);
  EXPECT_NEAR(fx[3], 10.0 * kR, 1e-15);
  EXPECT_NEAR(fy[3], 10.0 * kR, 1e-15);
}

// A ring of 12 touching disks encloses a large void; a 13th disk touches ring disks 0 and 1
// (an equilateral triangle) and protrudes into the void. The void's loop wraps around it: its
// exposed arc spans 300 degrees (a major arc). The chord rule must give the exact arc integral
// -P R int n dtheta over that arc: magnitude P * (distance between its contact points) = P R,
// pointing from its centre towards the chord, i.e. away from the void, through the centre.
TEST(PressureForces, MajorArcPushesParticleAwayFromVoid) {
  constexpr double kR = 1.0;
  constexpr int kRing = 12;
  const double pi = std::numbers::pi;
  const double ring_radius = kR / std::sin(pi / kRing);
  Packing p;
  for (int k = 0; k < kRing; ++k) {
    const double a = 2.0 * pi * k / kRing;
    p.Add(ring_radius * std::cos(a), ring_radius * std::sin(a), kR);
  }
  const double mid = pi / kRing;  // direction of the midpoint of ring disks 0 and 1
  const double inner = ring_radius * std::cos(mid) - std::sqrt(3.0) * kR;
  p.Add(inner * std::cos(mid), inner * std::sin(mid), kR);
  const Detected d = Detect(std::move(p));
  ASSERT_EQ(d.domains.num_domains(), 2u);  // the void and the triangle
  const std::size_t protruding = kRing;
  const std::size_t void_domain =
      d.domains.apparent_volume[0] > d.domains.apparent_volume[1] ? 0 : 1;

  constexpr double kVoidPressure = 2.5e5;
  std::vector<double> pressure(2, 0.0);
  pressure[void_domain] = kVoidPressure;
  std::vector<double> fx(d.packing.size(), 0.0), fy(d.packing.size(), 0.0);
  ASSERT_TRUE(AddPressureForces(ViewOf(d.packing), d.domains, pressure, {}, fx, fy).ok());

  // Independent reference: midpoint quadrature of -P R (cos t, sin t) over the exposed arc, which
  // runs counter-clockwise from the contact with disk 1 round the void side to the contact with
  // disk 0 (as seen from the protruding disk's centre).
  const double cx = d.packing.x[protruding], cy = d.packing.y[protruding];
  auto angle_to = [&](std::size_t other) {
    return std::atan2(d.packing.y[other] - cy, d.packing.x[other] - cx);
  };
  const double from = angle_to(1);
  double to = angle_to(0);
  while (to < from) to += 2.0 * pi;
  EXPECT_NEAR((to - from) * 180.0 / pi, 300.0, 1e-9) << "the exposed arc is a major arc";
  constexpr int kSteps = 200000;
  double qx = 0.0, qy = 0.0;
  for (int s = 0; s < kSteps; ++s) {
    const double t = from + (to - from) * (s + 0.5) / kSteps;
    qx -= kVoidPressure * kR * std::cos(t) * (to - from) / kSteps;
    qy -= kVoidPressure * kR * std::sin(t) * (to - from) / kSteps;
  }
  // Midpoint rule error ~ (h^2/24) |F| with h = 5.2/2e5: ~3e-11 relative.
  EXPECT_NEAR(fx[protruding], qx, 1e-9 * kVoidPressure * kR);
  EXPECT_NEAR(fy[protruding], qy, 1e-9 * kVoidPressure * kR);
  EXPECT_NEAR(std::hypot(fx[protruding], fy[protruding]), kVoidPressure * kR,
              1e-12 * kVoidPressure * kR);
  // Away from the void: outwards from the ring centre, along the radius through the particle.
  const double radial = (fx[protruding] * cx + fy[protruding] * cy) / std::hypot(cx, cy);
  EXPECT_NEAR(radial, kVoidPressure * kR, 1e-12 * kVoidPressure * kR);
}

// The contact point with one division of selected operands (ContactFraction), and with no branch
// at all (ContactFractionNoBranch, the vector loops' form), give the bits of the two rules written
// out with branches, as docs/physics.md §2.5 states them, on random pairs: equal and unequal radii,
// gaps, shallow and deep overlaps (clamped), coincident centres. Fails if a select picks the
// other rule's operand or the clamp's order changes.
TEST(PressureForces, ContactFractionIsTheTwoRulesBitForBit) {
  const auto two_rules = [](double r_lo, double r_hi, double d2) {
    if (!(d2 > 0.0)) return 0.5;
    const double sum = r_lo + r_hi;
    const double f = d2 < sum * sum ? 0.5 + (r_lo * r_lo - r_hi * r_hi) / (2.0 * d2)
                                    : 0.5 + (r_lo - r_hi) / (2.0 * std::sqrt(d2));
    return std::clamp(f, 0.0, 1.0);
  };
  std::mt19937_64 rng(20261205);
  std::uniform_real_distribution<double> radius(0.1, 2.0), reach(0.0, 1.6);
  int overlaps = 0, gaps = 0, clamped = 0;
  for (int k = 0; k < 200000; ++k) {
    const double r_lo = radius(rng);
    const double r_hi = k % 10 == 0 ? r_lo : radius(rng);
    const double d = k % 1000 == 0 ? 0.0 : reach(rng) * (r_lo + r_hi);
    const double d2 = d * d;
    const double expected = two_rules(r_lo, r_hi, d2);
    const double got = ContactFraction(r_lo, r_hi, d2);
    ASSERT_EQ(std::bit_cast<std::uint64_t>(got), std::bit_cast<std::uint64_t>(expected))
        << "r_lo " << r_lo << " r_hi " << r_hi << " d2 " << d2;
    // The vector loops' form: every operand computed and selected, a division by 0 at d2 = 0.
    const double no_branch = ContactFractionNoBranch(r_lo, r_hi, d2);
    ASSERT_EQ(std::bit_cast<std::uint64_t>(no_branch), std::bit_cast<std::uint64_t>(expected))
        << "no branch: r_lo " << r_lo << " r_hi " << r_hi << " d2 " << d2;
    overlaps += d2 < (r_lo + r_hi) * (r_lo + r_hi);
    gaps += !(d2 < (r_lo + r_hi) * (r_lo + r_hi));
    clamped += expected == 0.0 || expected == 1.0;
  }
  // Every branch of the reference was taken.
  EXPECT_GT(overlaps, 1000);
  EXPECT_GT(gaps, 1000);
  EXPECT_GT(clamped, 100);
}

// The contact point: mid-gap when apart, on the radical line when overlapping, r_lo from centre
// lo when touching (both rules meet there). Radii 1 and 2 along x.
TEST(PressureForces, ContactPointRules) {
  // Touching: d = 3, the point is 1 from the small disk.
  EXPECT_DOUBLE_EQ(ContactFraction(1.0, 2.0, 9.0) * 3.0, 1.0);
  // Gap 0.4 (d = 3.4): halfway across it, 1.2 from the small disk.
  EXPECT_NEAR(ContactFraction(1.0, 2.0, 3.4 * 3.4) * 3.4, 1.2, 1e-15);
  // Overlap (d = 2.5): radical line at (d^2 + 1 - 4) / (2 d) = 0.65 from the small disk.
  EXPECT_NEAR(ContactFraction(1.0, 2.0, 2.5 * 2.5) * 2.5, 0.65, 1e-15);
  // Continuity through first contact: 1e-9 either side moves the point by ~1e-9.
  const double below = ContactFraction(1.0, 2.0, (3.0 - 1e-9) * (3.0 - 1e-9)) * (3.0 - 1e-9);
  const double above = ContactFraction(1.0, 2.0, (3.0 + 1e-9) * (3.0 + 1e-9)) * (3.0 + 1e-9);
  EXPECT_NEAR(below, 1.0, 2e-9);
  EXPECT_NEAR(above, 1.0, 2e-9);
  // The arms of one pair are the same whichever disk is named first.
  Packing p;
  p.Add(0.0, 0.0, 1.0);
  p.Add(2.5, 0.3, 2.0);
  const ContactArms ab = ComputeContactArms(ViewOf(p), 0, 1);
  const ContactArms ba = ComputeContactArms(ViewOf(p), 1, 0);
  EXPECT_EQ(ab.ax, ba.bx);
  EXPECT_EQ(ab.ay, ba.by);
  EXPECT_EQ(ab.bx, ba.ax);
  EXPECT_EQ(ab.by, ba.ay);
  EXPECT_NEAR(ab.ax - ab.bx, 2.5, 1e-15);  // both arms end at the same point
  EXPECT_NEAR(ab.ay - ab.by, 0.3, 1e-15);
}

TEST(PressureForces, RejectsBadSizesWithoutWriting) {
  const Detected d = Detect(coupling_test::Square(3, 3, 1.0));
  std::vector<double> fx(d.packing.size(), 0.0), fy(d.packing.size(), 0.0);
  const std::vector<double> too_few(d.domains.num_domains() - 1, 1.0);
  const Status s = AddPressureForces(ViewOf(d.packing), d.domains, too_few, {}, fx, fy);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("coupling.pressure_forces.domain_pressure"), std::string::npos)
      << s.message();
  std::vector<double> short_fx(2, 0.0);
  const std::vector<double> ok(d.domains.num_domains(), 1.0);
  EXPECT_EQ(AddPressureForces(ViewOf(d.packing), d.domains, ok, {}, short_fx, fy).code(),
            StatusCode::kInvalidArgument);
  for (double f : fx) EXPECT_EQ(f, 0.0);
}

TEST(PressureForces, DeterministicBitForBit) {
  const Detected d = Detect(coupling_test::Random(11), 1e-2);
  std::vector<double> pressure(d.domains.num_domains());
  for (std::size_t k = 0; k < pressure.size(); ++k)
    pressure[k] = 1e5 + 37.0 * static_cast<double>(k % 17);
  std::vector<double> a(d.packing.size(), 0.0), b(d.packing.size(), 0.0);
  std::vector<double> c(d.packing.size(), 0.0), e(d.packing.size(), 0.0);
  ASSERT_TRUE(AddPressureForces(ViewOf(d.packing), d.domains, pressure, {}, a, b).ok());
  ASSERT_TRUE(AddPressureForces(ViewOf(d.packing), d.domains, pressure, {}, c, e).ok());
  EXPECT_EQ(a, c);
  EXPECT_EQ(b, e);
}

// Bind pairs the two face walks of every loop contact; a network in which some contact is not
// walked once each way is not a face decomposition, and the per-contact rule would silently give
// wrong forces. Two tamperings of a detected lattice: domain 0's loop reversed (particles and
// their contacts), so each of its contacts is walked twice in the same direction, and domain 0
// listed twice, so each of its contacts is walked three times. Both are refused naming the
// lowest contact id of that loop (the walks are checked in ascending contact order).
TEST(PressureForces, KernelBindRefusesContactsNotWalkedOnceEachWay) {
  const Detected d = Detect(coupling_test::Square(4, 4, 1.0));
  ASSERT_EQ(d.domains.num_domains(), 9u);
  PressureForceKernel kernel;
  ASSERT_TRUE(kernel.Bind(d.domains, d.packing.size()).ok());
  const auto begin = static_cast<std::size_t>(d.domains.loop_offsets[0]);
  const auto end = static_cast<std::size_t>(d.domains.loop_offsets[1]);
  ASSERT_EQ(end - begin, 4u);
  const std::int32_t lowest = *std::min_element(d.domains.loop_contacts.begin() + begin,
                                                d.domains.loop_contacts.begin() + end);
  const std::string message = "coupling.pressure_forces.network: contact " +
                              std::to_string(lowest) +
                              " is not walked exactly once in each direction by the face loops";

  // Reversed: p_{n-1} .. p_0; the contact after p_k in the new order is the one before it.
  DomainNetwork reversed = d.domains;
  const std::size_t n = end - begin;
  for (std::size_t m = 0; m < n; ++m) {
    reversed.loop_particles[begin + m] = d.domains.loop_particles[end - 1 - m];
    reversed.loop_contacts[begin + m] = d.domains.loop_contacts[begin + (2 * n - 2 - m) % n];
  }
  const Status s1 = kernel.Bind(reversed, d.packing.size());
  EXPECT_EQ(s1.code(), StatusCode::kInternal);
  EXPECT_EQ(s1.message(), message);

  DomainNetwork doubled = d.domains;
  for (std::size_t q = begin; q < end; ++q) {
    doubled.loop_particles.push_back(d.domains.loop_particles[q]);
    doubled.loop_contacts.push_back(d.domains.loop_contacts[q]);
  }
  doubled.loop_offsets.push_back(static_cast<std::int32_t>(doubled.loop_particles.size()));
  doubled.apparent_volume.push_back(d.domains.apparent_volume[0]);
  const Status s2 = kernel.Bind(doubled, d.packing.size());
  EXPECT_EQ(s2.code(), StatusCode::kInternal);
  EXPECT_EQ(s2.message(), message);
  // A negative contact id is named (it has no place among the contacts).
  DomainNetwork negative = d.domains;
  negative.loop_contacts[begin + 1] = -3;
  const Status s3 = kernel.Bind(negative, d.packing.size());
  EXPECT_EQ(s3.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(s3.message(), "coupling.pressure_forces.network.loop_contacts[" +
                              std::to_string(begin + 1) + "]: contact id -3 is negative");
  // AddPressureForces binds the same way: refused, nothing added.
  std::vector<double> fx(d.packing.size(), 0.0), fy(d.packing.size(), 0.0);
  const std::vector<double> pressure(reversed.num_domains(), 1e5);
  EXPECT_EQ(AddPressureForces(ViewOf(d.packing), reversed, pressure, {}, fx, fy).code(),
            StatusCode::kInternal);
  for (std::size_t i = 0; i < fx.size(); ++i) {
    EXPECT_EQ(fx[i], 0.0);
    EXPECT_EQ(fy[i], 0.0);
  }
}

// The chord rule per loop entry (pressure_forces.h): particle k of a face loop feels
// P (t_y, -t_x), t = c_{k,k+1} - c_{k-1,k} from its centre. An independent reference for the
// per-contact kernel, summed in another order, so it agrees to round-off only.
void ChordRuleReference(const Detected& d, std::span<const double> slot, std::vector<double>* fx,
                        std::vector<double>* fy) {
  const ParticleView view = ViewOf(d.packing);
  auto walk = [&](std::span<const std::int32_t> offsets, std::span<const std::int32_t> loop,
                  auto slot_of) {
    for (std::size_t f = 0; f + 1 < offsets.size(); ++f) {
      const auto b = static_cast<std::size_t>(offsets[f]);
      const auto e = static_cast<std::size_t>(offsets[f + 1]);
      for (std::size_t q = b; q < e; ++q) {
        const std::int32_t k = loop[q];
        const std::int32_t prev = loop[q > b ? q - 1 : e - 1];
        const std::int32_t next = loop[q + 1 < e ? q + 1 : b];
        const ContactArms to_next = ComputeContactArms(view, k, next);
        const ContactArms to_prev = ComputeContactArms(view, k, prev);
        const double tx = to_next.ax - to_prev.ax, ty = to_next.ay - to_prev.ay;
        const double p = slot[slot_of(f, q)];
        (*fx)[static_cast<std::size_t>(k)] += p * ty;
        (*fy)[static_cast<std::size_t>(k)] -= p * tx;
      }
    }
  };
  const std::size_t num_domains = d.domains.num_domains();
  walk(d.domains.loop_offsets, d.domains.loop_particles,
       [](std::size_t f, std::size_t) { return f; });
  walk(d.domains.outer_offsets, d.domains.outer_particles,
       [num_domains](std::size_t, std::size_t q) { return num_domains + q; });
}

// The coupled loop binds the kernel once per topology and applies it at every flow update. One
// bound kernel applied to three sets of random per-domain and per-arc pressures, adding onto
// forces that are not zero (Apply adds, like AddPressureForces), gives AddPressureForces' forces
// bit for bit each time: Apply keeps no state between calls. Both agree with the per-entry chord
// rule to round-off (1e-12 P R), which shows the forces are not trivially equal.
TEST(PressureForces, BoundKernelMatchesAddPressureForcesBitForBit) {
  const Detected d = Detect(coupling_test::Random(19), 1e-2);
  const std::size_t n = d.packing.size();
  const std::size_t num_domains = d.domains.num_domains();
  ASSERT_GT(num_domains, 100u);
  PressureForceKernel kernel;
  ASSERT_TRUE(kernel.Bind(d.domains, n).ok());
  ASSERT_EQ(kernel.num_slots(), num_domains + d.domains.outer_particles.size());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> pressure(0.0, 2e5), offset(-50.0, 50.0);
  double r_max = 0.0;
  for (const double r : d.packing.radius) r_max = std::max(r_max, r);
  for (int round = 0; round < 3; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    std::vector<double> slot(kernel.num_slots());
    for (double& p : slot) p = pressure(rng);
    const std::span<const double> domain_p(slot.data(), num_domains);
    const std::span<const double> arc_p(slot.data() + num_domains, slot.size() - num_domains);
    std::vector<double> start_x(n), start_y(n);
    for (std::size_t i = 0; i < n; ++i) {
      start_x[i] = offset(rng);
      start_y[i] = offset(rng);
    }
    std::vector<double> kx = start_x, ky = start_y, ax = start_x, ay = start_y;
    kernel.Apply(ViewOf(d.packing), slot.data(), kx.data(), ky.data());
    ASSERT_TRUE(AddPressureForces(ViewOf(d.packing), d.domains, domain_p, arc_p, ax, ay).ok());
    EXPECT_EQ(kx, ax);
    EXPECT_EQ(ky, ay);
    std::vector<double> rx = start_x, ry = start_y;
    ChordRuleReference(d, slot, &rx, &ry);
    double worst = 0.0, largest = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      worst = std::max(worst, std::hypot(kx[i] - rx[i], ky[i] - ry[i]));
      largest = std::max(largest, std::hypot(kx[i] - start_x[i], ky[i] - start_y[i]));
    }
    EXPECT_LT(worst, 1e-12 * 2e5 * r_max);
    EXPECT_GT(largest, 1e3 * r_max) << "random pressures push the particles";
  }
}

// Threads: the forces go to per-side slots, then each particle adds its own in contact order; the
// forces must be the one-thread bits on any thread count, in a team smaller than asked for, and
// with the last ids written to the wall-vertex arrays.
TEST(PressureForces, KernelGivesTheSameBitsOnAnyThreadCount) {
  const Detected d = Detect(coupling_test::Hex(80, 80, 1.0), 1e-2);
  const std::size_t n = d.packing.size();
  PressureForceKernel kernel;
  ASSERT_TRUE(kernel.Bind(d.domains, n).ok());
  ASSERT_GT(kernel.num_contacts(), 8192u) << "small enough for the one-thread path";
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pressure(0.0, 2e5);
  std::vector<double> slot(kernel.num_slots());
  for (double& p : slot) p = pressure(rng);
  const std::size_t vertices = 40;  // ids n - 40 .. n - 1 as wall vertices
  struct Output {
    std::vector<double> fx, fy, vx, vy;
    bool operator==(const Output&) const = default;
  };
  const int before = omp_get_max_threads();
  const auto apply = [&](int threads) {
    omp_set_num_threads(threads);
    Output out{std::vector<double>(n, 1.0), std::vector<double>(n, -1.0),
               std::vector<double>(vertices, 0.5), std::vector<double>(vertices, -0.5)};
    kernel.Apply(ViewOf(d.packing), slot.data(),
                 {out.fx.data(), out.fy.data(), n - vertices, out.vx.data(), out.vy.data()});
    return out;
  };
  const Output one = apply(1);
  EXPECT_NE(one.vx, std::vector<double>(vertices, 0.5)) << "the vertices are pushed";
  EXPECT_TRUE(apply(2) == one);
  EXPECT_TRUE(apply(3) == one);
  EXPECT_TRUE(apply(2) == one);  // the lists rebuilt for 2 again
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(0);
  EXPECT_TRUE(apply(3) == one);
  omp_set_max_active_levels(levels);
  omp_set_num_threads(before);
}

// The threaded path's per-particle lists are made by its first call after a Bind: bound again to
// another network after a threaded call, the kernel must not use the old network's lists (its
// contacts and particles differ in number), and the threads must still give the one-thread bits.
TEST(PressureForces, KernelBoundAgainMakesItsThreadedListsAgain) {
  const int before = omp_get_max_threads();
  PressureForceKernel kernel;
  const auto forces = [&](const Detected& d, int threads) {
    const std::size_t n = d.packing.size();
    std::vector<double> slot(kernel.num_slots());
    for (std::size_t k = 0; k < slot.size(); ++k) slot[k] = 1e3 * static_cast<double>(k % 17);
    std::vector<double> fx(n, 0.0), fy(n, 0.0);
    omp_set_num_threads(threads);
    kernel.Apply(ViewOf(d.packing), slot.data(), fx.data(), fy.data());
    fx.insert(fx.end(), fy.begin(), fy.end());
    return fx;
  };
  const Detected first = Detect(coupling_test::Hex(80, 80, 1.0), 1e-2);
  ASSERT_TRUE(kernel.Bind(first.domains, first.packing.size()).ok());
  const std::vector<double> first_one = forces(first, 1);
  EXPECT_EQ(forces(first, 2), first_one);
  const Detected second = Detect(coupling_test::Hex(96, 72, 1.0), 1e-2);
  ASSERT_NE(second.packing.size(), first.packing.size());
  ASSERT_TRUE(kernel.Bind(second.domains, second.packing.size()).ok());
  ASSERT_GT(kernel.num_contacts(), 8192u) << "small enough for the one-thread path";
  const std::vector<double> second_two = forces(second, 2);
  const std::vector<double> second_one = forces(second, 1);
  EXPECT_EQ(second_two, second_one);
  EXPECT_NE(second_one, std::vector<double>(second_one.size(), 0.0)) << "the forces are not all 0";
  omp_set_num_threads(before);
}

}  // namespace
}  // namespace seep::core
