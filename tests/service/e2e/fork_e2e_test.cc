// Branching from a checkpoint through the real seepd and seep (issue 16): `seep fork` of a
// mid-run checkpoint with the same stages ends with the parent's state hash; three forks of a
// prepared box, each lifting the lid at another speed, end in the order of their speeds, also
// when the parent is deleted while they run; `seep show` names parents and children; refusals
// point at the file and line (or name from_step) and store nothing.
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "../test_support.h"
#include "seep/v1/scene.pb.h"
#include "seepd_fixture.h"

namespace seep::testing {
namespace {

using nlohmann::json;

// seepd checkpoints every 500 steps and keeps them all: the staged box (about 1400 steps) has
// checkpoints at 500 (in its first stage), 1000 (in its last) and its final state.
class ForkE2eTest : public SeepdFixture {
 protected:
  std::vector<std::string> ExtraSeepdFlags() const override {
    return {"--checkpoint-every-steps", "500", "--checkpoints-kept", "100"};
  }

  static v1::Scene StagedBox() { return TestDataScene("staged_box.textproto"); }
  std::string WriteScene(const std::string& name, const v1::Scene& scene) {
    std::string text;
    EXPECT_TRUE(google::protobuf::TextFormat::PrintToString(scene, &text));
    return Write(name, text);
  }

  // Runs `args` (submit or fork, with --watch), expects success and returns the new job's id.
  std::string RunToTheEnd(std::vector<std::string> args) {
    args.push_back("--watch");
    const CommandResult run = Seep(args);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return JobIdFrom(run.output);
  }
  std::size_t JobCount() { return Json({"list"}).size(); }
};

TEST_F(ForkE2eTest, AForkWithTheSameStagesEndsWithTheParentsStateHash) {
  const std::string file = WriteScene("box.textproto", StagedBox());
  const std::string parent = RunToTheEnd({"submit", file});
  const std::string fork = RunToTheEnd({"fork", parent, "--step", "500", file});
  ASSERT_FALSE(fork.empty());
  const json parent_job = Json({"show", parent});
  const json fork_job = Json({"show", fork});
  EXPECT_EQ(fork_job["result"]["state_sha256"], parent_job["result"]["state_sha256"]);
  EXPECT_EQ(fork_job["result"]["state_sha256"].get<std::string>().size(), 64u);
  EXPECT_EQ(fork_job["parent_job_id"], parent);
  EXPECT_EQ(fork_job["parent_step"], "500");  // uint64 in proto JSON: a string
  EXPECT_EQ(parent_job["child_job_ids"], json::array({fork}));
  EXPECT_NE(Seep({"show", fork}).output.find("parent    " + parent + " (step 500)\n"),
            std::string::npos);
  EXPECT_NE(Seep({"show", parent}).output.find("children  " + fork + "\n"), std::string::npos);

  // Refused: each names the file's line or the option, exits 3 and stores nothing.
  const std::size_t jobs = JobCount();
  v1::Scene wider = StagedBox();
  wider.mutable_packing()->mutable_lattice()->set_columns(9);
  const std::string wider_file = WriteScene("wider.textproto", wider);
  CommandResult refused = Seep({"fork", parent, "--step", "500", wider_file});
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  EXPECT_NE(
      refused.output.find(wider_file + ":2: scene.packing: differs from the parent job " + parent),
      std::string::npos)
      << refused.output;
  refused = Seep({"fork", parent, "--step", "501", file});
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  EXPECT_NE(refused.output.find("seep: fork: from_step: job " + parent +
                                " has no checkpoint at step 501; its checkpoints are at steps "
                                "500, 1000, "),
            std::string::npos)
      << refused.output;
  refused = Seep({"fork", "j-0123456789abcdef", file});
  EXPECT_EQ(refused.exit_code, 5) << refused.output;
  EXPECT_EQ(JobCount(), jobs);
}

// One prepared sample feeds many runs: the parent confines the box and lets it rest; each fork
// adds a lift of the lid at its own speed for 2 ms, so the lid ends v x 2 ms above where the
// rest left it, in the order of the speeds. The parent is deleted while the forks are queued or
// running: they have their own copies of its checkpoint.
TEST_F(ForkE2eTest, ThreeForksOfAPreparedBoxEndInTheOrderOfTheirLidSpeeds) {
  v1::Scene prepare = StagedBox();
  prepare.mutable_stages()->RemoveLast();  // confine, rest
  prepare.set_name("prepare");
  const std::string parent = RunToTheEnd({"submit", WriteScene("prepare.textproto", prepare)});
  const std::vector<double> speeds = {0.01, 0.04, 0.02};  // m/s outwards
  std::vector<std::string> forks;
  for (const double speed : speeds) {
    v1::Scene lift = prepare;
    lift.set_name("lift-" + std::to_string(speed));
    v1::Stage* stage = lift.add_stages();
    stage->set_name("lift");
    v1::StageWall* lid = stage->add_walls();
    lid->set_wall(3);
    lid->mutable_normal_velocity_m_s()->set_value(-speed);  // the lid's normal points inwards
    stage->add_end()->set_duration_s(2e-3);
    const CommandResult run = Seep(
        {"fork", parent, WriteScene("lift-" + std::to_string(forks.size()) + ".textproto", lift)});
    ASSERT_EQ(run.exit_code, 0) << run.output;
    forks.push_back(JobIdFrom(run.output));
  }
  const json parent_job = Json({"show", parent});
  EXPECT_EQ(parent_job["child_job_ids"], json(forks));
  const std::string shown = Seep({"show", parent}).output;
  EXPECT_NE(shown.find("children  " + forks[0] + ", " + forks[1] + ", " + forks[2] + "\n"),
            std::string::npos)
      << shown;
  const double rested = parent_job["result"]["metrics"]["top_wall_position_m"].get<double>();
  const CommandResult deleted = Seep({"delete", parent});
  EXPECT_EQ(deleted.exit_code, 0) << deleted.output;

  std::vector<double> lifted;
  for (const std::string& fork : forks) {
    const CommandResult watched = Seep({"watch", fork});
    ASSERT_EQ(watched.exit_code, 0) << watched.output;
    const json job = Json({"show", fork});
    EXPECT_EQ(job["parent_job_id"], parent);  // kept after the parent was deleted
    const json& metrics = job["result"]["metrics"];
    EXPECT_EQ(metrics["stages_ended"].get<double>(), 3.0);
    // The fork started where the parent ended: the rest's lid position is the parent's last.
    EXPECT_EQ(metrics["stage2_top_wall_position_m"].get<double>(), rested);
    lifted.push_back(metrics["top_wall_position_m"].get<double>() - rested);
  }
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    // v x (2 ms + at most one step): the stage ends at the first step past its duration.
    EXPECT_NEAR(lifted[i], speeds[i] * 2e-3, speeds[i] * 1e-5) << "speed " << speeds[i];
  }
  EXPECT_LT(lifted[0], lifted[2]);  // 0.01 < 0.02 < 0.04 m/s
  EXPECT_LT(lifted[2], lifted[1]);
}

}  // namespace
}  // namespace seep::testing
