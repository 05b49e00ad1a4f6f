// A disk launched sliding along a frictional floor: while it slips, friction mu m g decelerates
// it at mu g and spins it up at 2 mu g / R; it rolls once v = omega R, i.e. after
// t_roll = v0 / (3 mu g), at v = 2 v0 / 3 (independent of mu: angular momentum about the
// contact point is conserved).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dem_test_util.h"

namespace seep::core {
namespace {

using dem_test::MakeContacts;
using dem_test::MakeDisks;

TEST(DemFriction, SlidingDiskDeceleratesAtMuGThenRollsAtTwoThirds) {
  const double r = 0.5, g = 10.0, mu = 0.4, v0 = 2.0;
  const double kn = 1.0e6;
  DemParticles p = MakeDisks({{0.0, r, r}}, 1.0);
  // Start at the static overlap m g / kn so that the normal force is already m g.
  p.y[0] = r - p.mass[0] * g / kn;
  p.vx[0] = v0;
  DemContactSettings settings;
  settings.law.kn = kn;
  settings.law.kt = 2.0 / 7.0 * kn;
  settings.law.friction = mu;
  settings.law.gamma_n = 0.5 * 2.0 * std::sqrt(kn / p.mass[0]);  // damp any normal oscillation
  settings.skin = 0.1;
  DemContactForces contacts = MakeContacts(settings);
  std::vector<DemWall> walls{*MakeWall(0.0, 0.0, 0.0, 1.0)};
  DemStepOptions options;
  options.dt = 1.0e-5;
  options.gravity_y = -g;
  DemCounters counters;
  ASSERT_TRUE(ComputeDemForces(&p, walls, &contacts, options, &counters).ok());
  const double t_roll = v0 / (3.0 * mu * g);  // 0.1667 s
  // Deceleration measured between 0.2 t_roll and 0.8 t_roll (well inside the slip phase, after
  // the tangential spring has reached the Coulomb cap within ~50 steps).
  const int s1 = static_cast<int>(0.2 * t_roll / options.dt);
  const int s2 = static_cast<int>(0.8 * t_roll / options.dt);
  const int s_end = static_cast<int>(2.0 * t_roll / options.dt);
  double v1 = 0.0, v2 = 0.0;
  for (int s = 1; s <= s_end; ++s) {
    ASSERT_TRUE(DemStep(&p, &walls, &contacts, options, &counters).ok());
    if (s == s1) v1 = p.vx[0];
    if (s == s2) v2 = p.vx[0];
  }
  const double decel = (v1 - v2) / ((s2 - s1) * options.dt);
  // While slipping the friction force is exactly mu fn and fn = m g up to the damped normal
  // oscillation (started at equilibrium): 1e-3 relative.
  EXPECT_NEAR(decel, mu * g, 1e-3 * mu * g);
  // Rolling: the tangential spring (no tangential damping) takes the friction force mu m g it
  // carried at the end of the slip and oscillates about zero in the rolling mode, whose mass is
  // m_t = m / 3 (1/m_t = 1/m + R^2/I) and frequency w_t = sqrt(kt / m_t). That leaves an
  // undamped oscillation of the slip speed v + omega R of amplitude mu m g / (m_t w_t) and of
  // the centre speed of amplitude mu g / w_t (the analytic bounds, 10% margin).
  const double w_t = std::sqrt(settings.law.kt * 3.0 / p.mass[0]);
  EXPECT_NEAR(p.vx[0], 2.0 * v0 / 3.0, 1.1 * mu * g / w_t);
  EXPECT_NEAR(p.omega[0] * r, -p.vx[0], 1.1 * 3.0 * mu * g / w_t);  // rolling: omega R = -v
  EXPECT_GT(counters.wall_evaluations, 0u);
  EXPECT_EQ(counters.pair_checks, 0u);  // one disk: no pairs
}

}  // namespace
}  // namespace seep::core
