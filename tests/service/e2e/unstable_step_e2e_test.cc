// An unstable step through the real seepd: the main example with its DEM step at the top of
// contacts.dt_safety's range (1.0, where its bonded lattice's stiffest mode is past velocity-
// Verlet's limit) ends FAILED with the energy guard's reason (core/run/energy_guard.h) naming
// the quantity, the step and the setting to change; seepd stays up and runs the next job.
#include <gtest/gtest.h>

#include "grpc_seepd_fixture.h"

namespace seep::testing {
namespace {

class UnstableStep : public GrpcSeepdTest {
 protected:
  UnstableStep() : GrpcSeepdTest("e2e-unstable") {}
};

TEST_F(UnstableStep, ATooLargeDtSafetyEndsFailedNamingTheEnergyTheStepAndTheSetting) {
  Start("data", {});
  v1::Scene scene = ExampleScene("anisotropic_fracturing.textproto");
  scene.set_name("unstable-step");
  bool planted = false;
  for (v1::Effect& effect : *scene.mutable_effects()) {
    if (!effect.has_contacts()) continue;
    effect.mutable_contacts()->set_dt_safety(1.0);
    planted = true;
  }
  ASSERT_TRUE(planted) << "the example has no contacts effect";
  const v1::Job failed = WaitTerminal(Submit(scene));
  ASSERT_EQ(failed.state(), v1::JOB_STATE_FAILED) << failed.DebugString();
  EXPECT_EQ(failed.error().code(), "FAILED_PRECONDITION") << failed.DebugString();
  const std::string& message = failed.error().message();
  for (const char* part : {"stability: at step ", "the disks' kinetic energy (",
                           "the step is unstable", "lower contacts.dt_safety (now 1)"}) {
    EXPECT_NE(message.find(part), std::string::npos) << part << " not in: " << message;
  }

  // seepd is still serving: the next job runs to the end.
  const v1::Job next = WaitTerminal(Submit(LatticeScene("after-the-failure", 4e-3)));
  EXPECT_EQ(next.state(), v1::JOB_STATE_SUCCEEDED) << next.DebugString();
}

}  // namespace
}  // namespace seep::testing
