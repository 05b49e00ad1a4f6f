// The sweep table, CSV and progress line of `seep sweep show` / `--watch` on a hand-built
// SweepStatus: exact text.
#include "sweep_table.h"

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

namespace seep::client {
namespace {

v1::SweepStatus TwoJobs() {
  v1::SweepStatus sweep;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(
      R"pb(
        id: "s-00000000000000ab"
        parameters: [ "boundary.inlet_pressure_pa", "solver.kind" ]
        counts { succeeded: 1 running: 1 }
        fraction_done: 0.625
        jobs {
          position: 0
          settings { path: "boundary.inlet_pressure_pa" number: 100000 }
          settings { path: "solver.kind" text: "SOLVER_KIND_STEADY" }
          job {
            id: "j-1"
            state: JOB_STATE_SUCCEEDED
            result {
              metrics { key: "permeability_m2" value: 4.1666666666666665e-14 }
              metrics { key: "domain_count" value: 77 }
            }
          }
        }
        jobs {
          position: 1
          settings { path: "boundary.inlet_pressure_pa" number: 2.5e5 }
          settings { path: "solver.kind" text: "a,\"b\"" }
          job { id: "j-2" state: JOB_STATE_RUNNING }
        }
      )pb",
      &sweep));
  return sweep;
}

TEST(SweepTable, CsvHasEveryNumberInFullPrecisionAndEmptyCellsForMissingMetrics) {
  std::string error;
  const auto metrics = SweepMetricColumns(TwoJobs(), {}, &error);
  EXPECT_EQ(error, "");
  EXPECT_EQ(metrics, (std::vector<std::string>{"domain_count", "permeability_m2"}));
  EXPECT_EQ(FormatSweepCsv(TwoJobs(), metrics),
            "position,job_id,state,boundary.inlet_pressure_pa,solver.kind,domain_count,"
            "permeability_m2\n"
            "0,j-1,SUCCEEDED,100000,SOLVER_KIND_STEADY,77,4.166666666666667e-14\n"
            "1,j-2,RUNNING,250000,\"a,\"\"b\"\"\",,\n");
}

TEST(SweepTable, TextTableIsAlignedWithNineDigitMetrics) {
  EXPECT_EQ(FormatSweepTable(TwoJobs(), {"permeability_m2"}),
            "POSITION  JOB  STATE      boundary.inlet_pressure_pa  solver.kind         "
            "permeability_m2\n"
            "0         j-1  SUCCEEDED  100000                      SOLVER_KIND_STEADY  "
            "4.16666667e-14\n"
            "1         j-2  RUNNING    250000                      a,\"b\"               -\n");
}

TEST(SweepTable, RequestedMetricsMustExistOnSomeJob) {
  std::string error;
  EXPECT_TRUE(SweepMetricColumns(TwoJobs(), {"permeability", "domain_count"}, &error).empty());
  EXPECT_EQ(error,
            "--metrics permeability: no job of sweep s-00000000000000ab has this metric (they "
            "have: domain_count, permeability_m2)");
}

TEST(SweepTable, ProgressLineCountsStatesAndPercent) {
  EXPECT_EQ(FormatSweepProgress(TwoJobs()),
            "RUNNING    62.5%  sweep s-00000000000000ab  2 jobs: 0 queued, 1 running, 1 "
            "succeeded, 0 failed, 0 cancelled");
  EXPECT_FALSE(SweepFinished(TwoJobs()));
}

}  // namespace
}  // namespace seep::client
