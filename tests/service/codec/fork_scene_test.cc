// CheckForkScene: what a fork's scene may change of its parent's (the name, progress_every and
// the stages after the checkpoint's current one) and how a refusal names the field.
#include "codec/fork_scene.h"

#include <gtest/gtest.h>

#include <string>

#include "test_support.h"

namespace seep::service {
namespace {

const v1::Scene& Parent() {
  static const v1::Scene scene = testing::TestDataScene("staged_box.textproto");
  return scene;
}

// The parent's checkpoint at step 500, in its first stage (index 0), or at its end.
constexpr ForkPoint kInFirstStage{"j-parent", 500, 0};
constexpr std::uint32_t kParentStages = 3;
const ForkPoint kAtTheEnd{"j-parent", 1407, kParentStages};

// The message of a refusal, which must be INVALID_ARGUMENT.
std::string Refusal(const v1::Scene& fork, const ForkPoint& at) {
  const core::Status s = CheckForkScene(Parent(), fork, at);
  EXPECT_EQ(s.code(), core::StatusCode::kInvalidArgument) << s.ToString();
  return s.message();
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

TEST(ForkScene, TheSameSceneContinuesFromAnyStageButTheEnd) {
  for (std::uint32_t stage = 0; stage < kParentStages; ++stage) {
    EXPECT_TRUE(CheckForkScene(Parent(), Parent(), {"j-parent", 500, stage}).ok()) << stage;
  }
  EXPECT_EQ(Refusal(Parent(), kAtTheEnd).rfind("scene.stages: nothing left to run", 0), 0u);
}

TEST(ForkScene, NameAndProgressIntervalMayChange) {
  v1::Scene fork = Parent();
  fork.set_name("another name");
  fork.mutable_solver()->set_progress_every(7);
  EXPECT_TRUE(CheckForkScene(Parent(), fork, kInFirstStage).ok());
}

TEST(ForkScene, ChangedPackingIsRefusedNamingIt) {
  v1::Scene fork = Parent();
  fork.mutable_packing()->mutable_lattice()->set_columns(9);
  const std::string message = Refusal(fork, kInFirstStage);
  EXPECT_TRUE(StartsWith(message, "scene.packing: differs from the parent job j-parent's"))
      << message;
}

// The first differing field in the scene's order is named, the solver's other fields count, and
// a field set to its default differs from one left unset.
TEST(ForkScene, TheFirstDifferingTopLevelFieldIsNamed) {
  v1::Scene fork = Parent();
  fork.mutable_solver()->set_dt_factor(0.8);
  fork.mutable_effects(2)->mutable_local_damping()->set_alpha(0.5);
  EXPECT_TRUE(StartsWith(Refusal(fork, kInFirstStage), "scene.solver:"));
  fork = Parent();
  fork.mutable_effects(2)->mutable_local_damping()->set_alpha(0.5);
  EXPECT_TRUE(StartsWith(Refusal(fork, kInFirstStage), "scene.effects:"));
  fork = Parent();
  fork.mutable_boundary();
  EXPECT_TRUE(StartsWith(Refusal(fork, kInFirstStage), "scene.boundary:"));
}

TEST(ForkScene, StagesThatHadBegunMustStayAndLaterOnesMayChange) {
  // In the second stage (index 1): the first two are fixed, the third is free.
  const ForkPoint in_rest{"j-parent", 800, 1};
  v1::Scene fork = Parent();
  fork.mutable_stages(2)->mutable_end(0)->set_duration_s(2e-3);
  fork.add_stages()->set_name("hold");
  EXPECT_TRUE(CheckForkScene(Parent(), fork, in_rest).ok());
  fork.mutable_stages(1)->mutable_end(0)->set_kinetic_energy_ratio(0.02);
  std::string message = Refusal(fork, in_rest);
  EXPECT_TRUE(StartsWith(message,
                         "scene.stages[1]: differs from the parent job j-parent's stage 2 "
                         "('rest'), which had begun at the checkpoint (step 800)"))
      << message;
  fork = Parent();
  fork.mutable_stages(0)->set_max_duration_s(0.3);
  message = Refusal(fork, in_rest);
  EXPECT_TRUE(StartsWith(message, "scene.stages[0]:")) << message;
  EXPECT_NE(message.find("'confine'), which had ended"), std::string::npos) << message;
  // Removing later stages is allowed; removing the current one is not.
  fork = Parent();
  fork.mutable_stages()->RemoveLast();
  EXPECT_TRUE(CheckForkScene(Parent(), fork, in_rest).ok());
  fork.mutable_stages()->RemoveLast();
  message = Refusal(fork, in_rest);
  EXPECT_TRUE(StartsWith(message,
                         "scene.stages: 1 stage(s), but the parent job j-parent's "
                         "checkpoint (step 800) is in its stage 2 ('rest')"))
      << message;
}

TEST(ForkScene, AFinishedRunNeedsAStageMoreAndKeepsAllOfItsOwn) {
  v1::Scene fork = Parent();
  v1::Stage* hold = fork.add_stages();
  hold->set_name("hold");
  hold->add_end()->set_duration_s(1e-3);
  EXPECT_TRUE(CheckForkScene(Parent(), fork, kAtTheEnd).ok());
  fork.mutable_stages(2)->set_name("raise");
  const std::string message = Refusal(fork, kAtTheEnd);
  EXPECT_TRUE(StartsWith(message, "scene.stages[2]:")) << message;
  EXPECT_NE(message.find("which had ended at the checkpoint (step 1407)"), std::string::npos)
      << message;
}

}  // namespace
}  // namespace seep::service
