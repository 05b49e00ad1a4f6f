// Two-disk head-on collision against the analytic linear spring-dashpot solution
//   delta(t) = v0/omega_d exp(-gamma t/2) sin(omega_d t),  omega_d = sqrt(kn/m_eff - gamma^2/4),
// so the contact lasts t_c = pi/omega_d and the normal restitution is e = exp(-gamma t_c / 2).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dem_test_util.h"
#include "seep/core/dem/contact_law.h"

namespace seep::core {
namespace {

using dem_test::MakeContacts;
using dem_test::MakeDisks;

struct CollisionOutcome {
  double duration = 0.0;     // time with gap < 0, measured at whole steps
  double restitution = 0.0;  // separation speed after / approach speed before
};

// Two equal disks (R = 0.5, density 1) approach at relative speed 2 v0 along x.
CollisionOutcome Collide(const ContactLawParams& law, double dt) {
  DemParticles p = MakeDisks({{0.0, 0.0, 0.5}, {1.0 + 1e-3, 0.0, 0.5}}, 1.0);
  const double v0 = 1.0;
  p.vx[0] = v0;
  p.vx[1] = -v0;
  DemContactSettings settings;
  settings.law = law;
  settings.skin = 0.05;
  DemContactForces contacts = MakeContacts(settings);
  std::vector<DemWall> walls;
  DemStepOptions options;
  options.dt = dt;
  DemCounters counters;
  EXPECT_TRUE(ComputeDemForces(&p, walls, &contacts, options, &counters).ok());
  int first = -1, last = -1;
  for (int step = 1; step < 200000; ++step) {
    EXPECT_TRUE(DemStep(&p, &walls, &contacts, options, &counters).ok());
    const double gap = (p.x[1] - p.x[0]) - 1.0;
    if (gap < 0.0) {
      if (first < 0) first = step;
      last = step;
    } else if (first >= 0) {
      break;
    }
  }
  CollisionOutcome out;
  // The contact starts between steps first-1 and first and ends between last and last+1; the
  // midpoint estimate is within dt/2 of the truth at each end, so within dt overall.
  out.duration = (last - first + 1) * dt;
  out.restitution = (p.vx[1] - p.vx[0]) / (2.0 * v0);
  return out;
}

TEST(DemCollision, DurationAndRestitutionMatchSpringDashpot) {
  ContactLawParams law;
  law.kn = 1.0e5;
  law.kt = 0.0;
  law.gamma_n = 200.0;
  const double m = std::acos(-1.0) * 0.25;  // pi R^2, R = 0.5
  const double m_eff = 0.5 * m;
  const double t_c = SpringDashpotContactDuration(law.kn, m_eff, law.gamma_n);
  const double e = SpringDashpotRestitution(law.kn, m_eff, law.gamma_n);
  const double dt = t_c / 1000.0;
  const CollisionOutcome out = Collide(law, dt);
  // Duration: counted at whole steps, so within one step (see Collide) -> 1e-3 relative.
  EXPECT_NEAR(out.duration, t_c, 1.0 * dt);
  // Restitution: velocity-Verlet with the force evaluated at half-step velocities has an O(dt)
  // error in the dissipated energy per unit gamma: |de| <= gamma dt ~ 200 * t_c/1000 (~0.003
  // of e here); the partial first and last steps add O(dt/t_c) = 1e-3. Tolerance 5e-3.
  EXPECT_NEAR(out.restitution, e, 5e-3);
  EXPECT_GT(e, 0.3);  // the case is really damped
  EXPECT_LT(e, 0.9);
}

TEST(DemCollision, CriticalRatioDampingGivesItsRestitution) {
  ContactLawParams law;
  law.kn = 1.0e5;
  law.damping_mode = NormalDampingMode::kCriticalRatio;
  law.damping_ratio = 0.2;
  const double m_eff = 0.5 * std::acos(-1.0) * 0.25;
  // gamma = 2 zeta sqrt(kn/m_eff)  =>  e = exp(-zeta pi / sqrt(1 - zeta^2)).
  const double zeta = law.damping_ratio;
  const double e = std::exp(-zeta * std::acos(-1.0) / std::sqrt(1.0 - zeta * zeta));
  const double gamma = 2.0 * zeta * std::sqrt(law.kn / m_eff);
  const double t_c = SpringDashpotContactDuration(law.kn, m_eff, gamma);
  const CollisionOutcome out = Collide(law, t_c / 1000.0);
  EXPECT_NEAR(out.duration, t_c, t_c / 1000.0);
  EXPECT_NEAR(out.restitution, e, 5e-3);  // as above
}

TEST(DemContactLaw, FrictionCapsTheShearHistory) {
  ContactLawParams law;
  law.kn = 1000.0;
  law.kt = 500.0;
  law.friction = 0.5;
  // overlap 0.01 -> fn = 10, cap 5. A trial spring force of 500 * 2 * 0.1 = 100 slips to 5.
  const ContactForce slip = EvaluateLinearContact(law, 0.01, 0.0, 2.0, 1.0, 0.0, 0.1);
  EXPECT_DOUBLE_EQ(slip.fn, 10.0);
  EXPECT_DOUBLE_EQ(slip.ft, 5.0);
  // Below the cap the spring sticks: ft = 0 + 500 * 0.01 * 0.1 = 0.5.
  const ContactForce stick = EvaluateLinearContact(law, 0.01, 0.0, 0.01, 1.0, 0.0, 0.1);
  EXPECT_DOUBLE_EQ(stick.ft, 0.5);
  // Reversing motion unloads the stored spring linearly from the capped value.
  const ContactForce back = EvaluateLinearContact(law, 0.01, 0.0, -0.02, 1.0, slip.ft, 0.1);
  EXPECT_DOUBLE_EQ(back.ft, 5.0 - 1.0);
}

TEST(DemContactLaw, RejectsBadParametersNamingTheField) {
  ContactLawParams law;
  law.kn = -1.0;
  const Status s = ValidateContactLawParams(law);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("dem.contact.kn"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace seep::core
