// How `seep watch` draws progress: the one-line bar for terminals and the durations in it, and
// the stage of a staged run in the bar, the plain lines and `seep show`.
#include "job_printer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>

namespace seep::client {
namespace {

v1::Job RunningJob(double fraction) {
  v1::Job job;
  job.set_state(v1::JOB_STATE_RUNNING);
  job.mutable_progress()->set_step(1234);
  job.mutable_progress()->set_time_s(0.0125);
  job.mutable_progress()->set_fraction_done(fraction);
  job.mutable_progress()->set_eta_s(125.0);
  (*job.mutable_progress()->mutable_latest())["inflow_m2_per_s"] = 2.5e-6;
  (*job.mutable_progress()->mutable_latest())["mass_balance_error"] = 1e-12;
  return job;
}

TEST(ProgressBar, ShowsStateBarPercentStepTimeEtaAndKeyMetrics) {
  const std::string line = FormatProgressBar(RunningJob(0.5), 200);
  // 24 cells, half of them filled at 50%.
  EXPECT_NE(line.find("RUNNING   [############............]  50.0%"), std::string::npos) << line;
  EXPECT_NE(line.find("step 1234"), std::string::npos) << line;
  EXPECT_NE(line.find("t = 0.0125 s"), std::string::npos) << line;
  EXPECT_NE(line.find("ETA 2m05s"), std::string::npos) << line;
  EXPECT_NE(line.find("q_in 2.5e-06"), std::string::npos) << line;
  EXPECT_NE(line.find("mass_err 1e-12"), std::string::npos) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos);
}

TEST(ProgressBar, IsCutToTheTerminalWidthSoACarriageReturnRedrawsIt) {
  // A line as wide as the terminal would wrap, and \r would then redraw only its last row.
  EXPECT_EQ(FormatProgressBar(RunningJob(0.25), 40).size(), 39u);
  EXPECT_LT(FormatProgressBar(RunningJob(0.25), 200).size(), 199u);
}

TEST(ProgressBar, FinishedJobHasAFullBarAndNoEta) {
  v1::Job job = RunningJob(1.0);
  job.set_state(v1::JOB_STATE_SUCCEEDED);
  const std::string line = FormatProgressBar(job, 200);
  EXPECT_NE(line.find("[########################] 100.0%"), std::string::npos) << line;
  EXPECT_EQ(line.find("ETA"), std::string::npos) << line;
}

TEST(ProgressBar, CalibrationCountsSolvesInsteadOfSimulatedTime) {
  v1::Job job = RunningJob(0.1);
  job.set_kind(v1::JOB_KIND_CALIBRATION);
  job.mutable_progress()->set_step(3);
  const std::string line = FormatProgressBar(job, 200);
  EXPECT_NE(line.find("solves 3"), std::string::npos) << line;
  EXPECT_EQ(line.find("t = "), std::string::npos) << line;
}

TEST(JobSummary, ShowsLabelsSortedByKeyAndAnEventAsOneLine) {
  v1::Job job = RunningJob(0.5);
  (*job.mutable_labels())["team"] = "flow";
  (*job.mutable_labels())["owner"] = "ana";
  EXPECT_NE(FormatJob(job).find("\nlabels    owner=ana,team=flow\n"), std::string::npos)
      << FormatJob(job);
  EXPECT_EQ(FormatJob(RunningJob(0.5)).find("labels"), std::string::npos);
  v1::JobHistoryEvent event;
  event.mutable_at()->set_seconds(1'700'000'000);
  event.set_kind("RESUMED");
  event.set_message("from ckpt-000000001000.bin at step 1000 of 4000");
  EXPECT_EQ(FormatJobEvent(event),
            "2023-11-14T22:13:20Z      RESUMED               from ckpt-000000001000.bin at step "
            "1000 of 4000");
}

v1::Job StagedJob() {
  v1::Job job = RunningJob(0.5);
  job.mutable_progress()->set_stage_index(2);
  job.mutable_progress()->set_stage_count(3);
  job.mutable_progress()->set_stage_name("inject");
  return job;
}

// The stage comes right after the percentage, before what a narrow terminal cuts off.
TEST(StageDisplay, BarShowsTheStageBeforeStepAndTime) {
  const std::string line = FormatProgressBar(StagedJob(), 200);
  EXPECT_NE(line.find("RUNNING   [############............]  50.0%  stage 2/3 inject  step 1234"),
            std::string::npos)
      << line;
  EXPECT_NE(FormatProgressBar(StagedJob(), 80).find("stage 2/3 inject"), std::string::npos);
}

TEST(StageDisplay, PlainLineShowsTheStageAfterThePercentage) {
  const std::string line = FormatProgress(StagedJob());
  EXPECT_NE(line.find(" 50.0%  stage 2/3 inject  ETA 125.0 s"), std::string::npos) << line;
}

TEST(StageDisplay, ShowHasAStageLineAfterProgress) {
  const std::string summary = FormatJob(StagedJob());
  EXPECT_NE(summary.find("%\nstage     2/3 inject\nbuild"), std::string::npos) << summary;
}

// An unnamed stage shows its number alone; a scene without stages shows nothing new.
TEST(StageDisplay, UnnamedStageAndSceneWithoutStages) {
  v1::Job unnamed = StagedJob();
  unnamed.mutable_progress()->clear_stage_name();
  EXPECT_EQ(FormatStage(unnamed.progress()), "2/3");
  EXPECT_NE(FormatProgress(unnamed).find("  stage 2/3  ETA"), std::string::npos)
      << FormatProgress(unnamed);
  const v1::Job plain = RunningJob(0.5);
  EXPECT_EQ(FormatStage(plain.progress()), "");
  for (const std::string& text :
       {FormatProgressBar(plain, 200), FormatProgress(plain), FormatJob(plain)}) {
    EXPECT_EQ(text.find("stage"), std::string::npos) << text;
  }
}

// A fork names its parent and the checkpoint step it started from; a parent lists its forks.
TEST(JobSummary, ShowsParentAndChildren) {
  v1::Job fork = RunningJob(0.5);
  fork.set_parent_job_id("j-1111111111111111");
  fork.set_parent_step(500);
  fork.add_child_job_ids("j-2222222222222222");
  fork.add_child_job_ids("j-3333333333333333");
  const std::string summary = FormatJob(fork);
  EXPECT_NE(summary.find("\nparent    j-1111111111111111 (step 500)\n"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("\nchildren  j-2222222222222222, j-3333333333333333\n"), std::string::npos)
      << summary;
  const std::string plain = FormatJob(RunningJob(0.5));
  EXPECT_EQ(plain.find("parent"), std::string::npos) << plain;
  EXPECT_EQ(plain.find("children"), std::string::npos) << plain;
}

// A job whose worker a Slurm job runs names that job, its node and its state.
TEST(JobSummary, ShowsTheSlurmJobOfItsWorker) {
  v1::Job job = RunningJob(0.5);
  job.mutable_batch()->set_system("slurm");
  job.mutable_batch()->set_job_id("4711");
  job.mutable_batch()->set_node("node17");
  job.mutable_batch()->set_state("RUNNING");
  const std::string summary = FormatJob(job);
  EXPECT_NE(summary.find("\nslurm     job 4711 on node17, RUNNING\n"), std::string::npos)
      << summary;
  // A worker started by hand in a Slurm job: seepd knows no state of it.
  job.mutable_batch()->clear_state();
  job.mutable_batch()->clear_node();
  EXPECT_NE(FormatJob(job).find("\nslurm     job 4711\n"), std::string::npos) << FormatJob(job);
  EXPECT_EQ(FormatJob(RunningJob(0.5)).find("slurm"), std::string::npos);
}

// A floor (_safe_above) warns below it, a ceiling (_safe_below) above it, each naming the number,
// its value and the bound; a number on the safe side, at its bound, or without its number
// warns of nothing; a stage's copy warns for the stage.
TEST(AccuracyWarnings, FloorsWarnBelowCeilingsAboveAndNamesTheNumberAndBound) {
  const std::map<std::string, double> metrics = {
      {"coupling_fluid_to_skeleton_stiffness", 12.5},
      {"coupling_fluid_to_skeleton_stiffness_safe_above", 50.0},
      {"coupling_bonded_dem_step_safety", 0.5},
      {"coupling_bonded_dem_step_safety_safe_below", 0.2},
      {"stage2_coupling_fluid_step_over_flow_interval", 1.0},  // at the bound: safe
      {"stage2_coupling_fluid_step_over_flow_interval_safe_above", 1.0},
      {"lonely_safe_below", 3.0},  // no number beside it
  };
  const std::string out = FormatAccuracyWarnings(metrics);
  EXPECT_NE(out.find("warning   coupling_fluid_to_skeleton_stiffness = 12.5 is below 50: "),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("warning   coupling_bonded_dem_step_safety = 0.5 is above 0.2: "),
            std::string::npos)
      << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 2) << out;
  // A staged run's copies fold into the whole run's line; a stage alone warns on its own.
  const std::string staged = FormatAccuracyWarnings({
      {"coupling_fluid_to_skeleton_stiffness", 0.5},
      {"coupling_fluid_to_skeleton_stiffness_safe_above", 50.0},
      {"stage1_coupling_fluid_to_skeleton_stiffness", 0.4},
      {"stage1_coupling_fluid_to_skeleton_stiffness_safe_above", 50.0},
      {"stage3_coupling_fluid_to_skeleton_stiffness", 0.6},
      {"stage3_coupling_fluid_to_skeleton_stiffness_safe_above", 50.0},
      {"stage2_coupling_fluid_step_over_flow_interval", 0.25},
      {"stage2_coupling_fluid_step_over_flow_interval_safe_above", 1.0},
  });
  EXPECT_NE(staged.find("warning   coupling_fluid_to_skeleton_stiffness = 0.5 is below 50 (and in "
                        "stage 1, 3): "),
            std::string::npos)
      << staged;
  EXPECT_NE(
      staged.find("warning   stage2_coupling_fluid_step_over_flow_interval = 0.25 is below 1: "),
      std::string::npos)
      << staged;
  EXPECT_EQ(std::count(staged.begin(), staged.end(), '\n'), 2) << staged;
  EXPECT_EQ(FormatAccuracyWarnings({{"coupling_bonded_dem_step_safety", 0.2},
                                    {"coupling_bonded_dem_step_safety_safe_below", 0.2}}),
            "");
}

TEST(Duration, SecondsMinutesHours) {
  EXPECT_EQ(FormatDuration(0.2), "1 s");  // never "0 s" for work that is still left
  EXPECT_EQ(FormatDuration(42.4), "42 s");
  EXPECT_EQ(FormatDuration(185.0), "3m05s");
  EXPECT_EQ(FormatDuration(7620.0), "2h07m");
  EXPECT_EQ(FormatDuration(-1.0), "?");
}

}  // namespace
}  // namespace seep::client
