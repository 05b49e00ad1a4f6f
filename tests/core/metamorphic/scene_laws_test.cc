// The laws of scene_laws.h over generated scenes (scene_generator.h): 200 seeds, each a scene of
// its own drawn across the feature space (about 65 s in one process, Release). A failure names the
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
  // The translation is a multiple of the snapping grid (scene_maps.h) of the order of the sample
  // (up to 0.25 m); the stop of the resume somewhere inside the run.
  const double tx = (static_cast<double>(seed % 7) - 3.0) * 0.0625 + 0.03125;
  const double ty = (static_cast<double>(seed % 5) - 2.0) * 0.046875;
  const double spread = RoundingSpread(g.scene, g.steps);
  std::printf("%s: %llu steps, one rounding moves the state by %.3g of its scale\n",
              g.scene.name.c_str(), static_cast<unsigned long long>(g.steps), spread);
  for (const SceneMap& map : {SceneMap{Turn::kNone, tx, ty}, SceneMap{Turn::kQuarter, 0.0, 0.0},
                              SceneMap{Turn::kMirrorX, 0.0, 0.0}}) {
    EXPECT_EQ(CheckIsometry(g.scene, g.steps, map, spread), "");
  }
  const SceneSpec scene = MaterialisedScene(g.scene);
  if (g.scene.solver.kind != SolverKind::kSteady) {
    const std::uint64_t stop_at = 1 + seed % (g.steps - 1);
    EXPECT_EQ(CheckResume(scene, g.steps, stop_at), "");
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
