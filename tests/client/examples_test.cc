// Every file in examples/ runs on a real seepd and SUCCEEDS: scenes through `seep submit`, the
// calibration file through `seep calibrate`, the sweep through `seep sweep submit`. The examples
// are the documentation users copy from, so a field renamed in the proto or a value the server
// rejects breaks this test first.
#include <algorithm>

#include "seepd_fixture.h"

namespace seep::testing {
namespace {

using ClientExamples = SeepdFixture;

TEST_F(ClientExamples, EveryExampleSucceedsOnARealSeepd) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(SEEP_EXAMPLES_DIR)) {
    const auto ext = entry.path().extension();
    if (ext == ".textproto" || ext == ".json") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 6u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
#ifdef SEEP_SANITIZED
    // Long physics (a minute or more each under AddressSanitizer); the Release suite runs them
    // here and checks their numbers in tests/service/physics/staged_examples_test.cc.
    const std::string stem = file.stem().string();
    if (stem == "anisotropic_fracturing" || stem == "terzaghi_two_steps" ||
        stem == "biaxial_shear_seepage") {
      continue;
    }
#endif
    std::ifstream in(file);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.find("\naxes {") != std::string::npos) {
      // A sweep: every job SUCCEEDED, on its one progress line.
      const CommandResult run = Seep({"sweep", "submit", file.string(), "--watch"});
      EXPECT_EQ(run.exit_code, 0) << run.output;
      EXPECT_TRUE(std::regex_search(
          run.output,
          std::regex("SUCCEEDED +100.0%  sweep s-[0-9a-f]{16} .* 0 failed, 0 cancelled")))
          << run.output;
      continue;
    }
    const bool calibration = text.find("target_permeabilities_m2") != std::string::npos;
    const CommandResult run =
        Seep({calibration ? "calibrate" : "submit", file.string(), "--watch"});
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("state     SUCCEEDED"), std::string::npos) << run.output;
  }
}

TEST_F(ClientExamples, Transient1dOutflowFollowsTheDiffusionSeries) {
  const CommandResult run = Seep({"submit", Example("transient_1d.textproto"), "--watch"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto job = Json({"show", JobIdFrom(run.output)});
  const auto& metrics = job["result"]["metrics"];
  // docs/physics.md §3.2 (a): q_out / q_steady = 1 + 2 sum (-1)^n exp(-n^2 pi^2 T) = 0.72292 at
  // T = c t / L^2 = 0.2. q_steady = k (H/L) p1 / mu with the sample's H = 3 x 2R (three rows of
  // domains) and L = 41 x 2R; k = a0^3 / (24 R).
  const double r = 1e-3;
  const double k = 1e-15 / (24.0 * r);
  const double steady = k * (3 * 2 * r) / (41 * 2 * r) * 1e5 / 1e-3;
  const double ratio = metrics["outflow_m2_per_s"].get<double>() / steady;
  RecordProperty("outflow_ratio", std::to_string(ratio));
  // The network of 40 cells along x is measured at 0.72343 (0.07% above the series: spatial
  // discretisation, docs/physics.md §3.2 quotes 0.13% of p1 at T = 0.1 on 20 cells). 0.5% allows
  // for a change of the explicit step count without hiding a wrong diffusivity (a wrong storage
  // volume changes c by 1/n_s = 4.7x and the ratio by far more).
  EXPECT_NEAR(ratio, 0.72292, 0.005 * 0.72292) << "outflow " << metrics["outflow_m2_per_s"];
}

// The funnel's lid is velocity-controlled: it has moved v t along its normal, to rounding.
TEST_F(ClientExamples, SegmentFunnelLidMovesVT) {
  const CommandResult run = Seep({"submit", Example("segment_funnel.textproto"), "--watch"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto job = Json({"show", JobIdFrom(run.output)});
  const auto& metrics = job["result"]["metrics"];
  const double t = metrics["simulated_time_s"].get<double>();
  EXPECT_NEAR(t, 0.1, 1e-4);
  EXPECT_NEAR(metrics["segment2_wall_position_m"].get<double>(), 0.02 * t, 1e-12);
  EXPECT_EQ(metrics["particle_count"].get<double>(), 48.0);
}

// Two boundary regions: all the fluid the well (a circle at 100 kPa) gives the sample leaves
// through the drain (a box at 0 Pa over the last column of domains), the sample being closed
// elsewhere. Conservation is the independent value: the direct solve's residual, about 1e-16 of a
// pipe's C P_w per domain times the condition number (~1e4 for 1700 unknowns), summed over the
// domains, leaves ~1e-12 of Q (measured 5e-13). The rate itself is this lattice's (2.5596e-6).
TEST_F(ClientExamples, RegionsTwoWellsDrainTakesWhatTheWellGives) {
  const CommandResult run = Seep({"submit", Example("regions_two_wells.textproto"), "--watch"});
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto job = Json({"show", JobIdFrom(run.output)});
  const auto& metrics = job["result"]["metrics"];
  const double drain = metrics["region_drain_flow_m2_per_s"].get<double>();
  const double well = metrics["region_well_flow_m2_per_s"].get<double>();
  EXPECT_NEAR(drain, -well, 1e-11 * drain);
  EXPECT_NEAR(drain, 2.5595587536e-6, 1e-9 * drain);
  EXPECT_EQ(metrics["region_well_domains"].get<double>(), 21.0);
  EXPECT_EQ(metrics["region_drain_domains"].get<double>(), 29.0);
}

}  // namespace
}  // namespace seep::testing
