// Scenes on which a law of scene_laws.h failed, kept as named tests (the bench found them; the
// seed reproduces the scene: seep_scene_laws_bench --seed N).
#include <gtest/gtest.h>

#include "scene_generator.h"
#include "scene_laws.h"

namespace seep::core::metamorphic {
namespace {

// A sealed box with a servo lid, bonds and re-detection, stopped at step 42 of 43: the critical
// step a resumed run reported (metric dt_crit_s) was the one its re-bind measured on the
// detection's volumes, not the last flow update's (3.51580e-5 against 3.51657e-5 s). The
// checkpoint keeps it now (checkpoint fields 38 and 39).
TEST(FoundByTheLaws, ResumeReportsTheCriticalStepOfTheLastFlowUpdate) {
  const GeneratedScene g = GenerateScene(1217);
  ASSERT_EQ(g.family, Family::kBox);
  EXPECT_EQ(CheckResume(LawScene(g.scene), g.steps, 42), "");
}

}  // namespace
}  // namespace seep::core::metamorphic
