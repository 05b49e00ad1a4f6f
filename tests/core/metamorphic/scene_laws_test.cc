// The laws of scene_laws.h over generated scenes (scene_generator.h): 200 seeds, each a scene of
// its own drawn across the feature space (about 37 s in one process, Release). A failure names the
// seed; the bench (bench/robustness/scene_laws_bench.cc --seed N) writes that scene's file to
// reproduce it.
#include "scene_laws.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "scene_generator.h"

namespace seep::core::metamorphic {
namespace {

class SceneLaws : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(SceneLaws, Hold) {
  const std::uint64_t seed = GetParam();
  const GeneratedScene g = GenerateScene(seed);
  SCOPED_TRACE(g.scene.name);
  const LawScene scene(g.scene);
  const double spread = RoundingSpread(scene, g.steps);
  std::printf("%s: %llu steps, one rounding moves the state by %.3g of its scale\n",
              g.scene.name.c_str(), static_cast<unsigned long long>(g.steps), spread);
  for (const SceneMap& map : {SeedTranslation(seed), SceneMap{Turn::kQuarter, 0.0, 0.0},
                              SceneMap{Turn::kMirrorX, 0.0, 0.0}}) {
    EXPECT_EQ(CheckIsometry(scene, g.steps, map, spread), "");
  }
  if (g.scene.solver.kind != SolverKind::kSteady) {
    EXPECT_EQ(CheckResume(scene, g.steps, SeedResumeStep(seed, g.steps)), "");
  }
  // One seed in four: two threads with every loop on the team wait at a barrier per loop, which a
  // neighbouring test process on the same cores makes slow (the bench runs it on every scene).
  if (seed % 4 == 0) {
    EXPECT_EQ(CheckThreads(scene, g.steps), "");
  }
  EXPECT_EQ(CheckBooks(scene, g.steps), "");
}

INSTANTIATE_TEST_SUITE_P(Generated, SceneLaws, ::testing::Range<std::uint64_t>(1, 201));

}  // namespace
}  // namespace seep::core::metamorphic
