// Chaos: 22 jobs (frozen packings on three solvers, and DEM scenes whose particles move, bonds
// break and domains merge) through a real seepd that is killed with SIGKILL eight times at
// seeded moments: at random wall times, and exactly between a checkpoint file and its record and
// between a result's series and its final write (seepd --test-crash-at). Every job must end
// SUCCEEDED with the final-state hash of an uninterrupted run.
#include <fmt/format.h>
#include <google/protobuf/text_format.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "grpc_seepd_fixture.h"

namespace seep::testing {
namespace {

v1::Scene Parse(const std::string& text) {
  v1::Scene scene;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &scene)) << text;
  return scene;
}

// A frozen lattice or random packing under a linear permeameter, a fraction of a second each;
// every third one reports progress at every step.
v1::Scene FrozenScene(int index, v1::SolverKind solver, const std::string& packing,
                      double dt_factor, double end_time_s) {
  v1::Scene scene = Parse(R"pb(
    fluid { viscosity_pa_s: 1e-3 bulk_modulus_pa: 2.2e9 }
    aperture { residual_aperture_m: 1e-5 reference_force_n: 1e3 gap_multiplier: 0.5 }
    boundary { axis: FLOW_AXIS_X inlet_pressure_pa: 1e5 }
    solver { storage: STORAGE_VOLUME_PORE }
  )pb");
  scene.set_name(fmt::format("chaos-frozen-{}", index));
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(packing, scene.mutable_packing()))
      << packing;
  v1::Solver* s = scene.mutable_solver();
  s->set_kind(solver);
  s->set_dt_factor(dt_factor);
  s->set_end_time_s(end_time_s);
  s->set_progress_every(index % 3 == 0 ? 1 : 0);
  return scene;
}

// The hydraulic-fracturing example on a smaller sample, cut short: moving particles, bonds,
// servo walls, re-detection; its checkpoints carry the whole DEM state.
v1::Scene MovingScene(int index, int columns, int rows, double end_time_s) {
  v1::Scene scene =
      Parse(ReadFile(std::string(SEEP_EXAMPLES_DIR) + "/hydraulic_fracturing.textproto"));
  scene.set_name(fmt::format("chaos-moving-{}", index));
  scene.mutable_packing()->mutable_lattice()->set_columns(columns);
  scene.mutable_packing()->mutable_lattice()->set_rows(rows);
  scene.mutable_solver()->set_end_time_s(end_time_s);
  return scene;
}

std::string Lattice(const char* kind, int columns, int rows) {
  return fmt::format("lattice {{ kind: {} columns: {} rows: {} radius_m: 1e-3 }}", kind, columns,
                     rows);
}

std::vector<v1::Scene> ChaosScenes() {
  std::vector<v1::Scene> scenes;
  int index = 0;
  for (const int columns : {30, 40, 50, 60, 70, 80}) {
    scenes.push_back(FrozenScene(index++, v1::SOLVER_KIND_EXPLICIT,
                                 Lattice("LATTICE_KIND_SQUARE", columns, 30), 0.9, 2e-2));
  }
  for (const int columns : {40, 60, 80, 100}) {
    scenes.push_back(FrozenScene(index++, v1::SOLVER_KIND_IMPLICIT,
                                 Lattice("LATTICE_KIND_HEX", columns, 50), 5, 5e-4));
  }
  for (const int seed : {1, 2, 3, 4}) {
    const std::string random = fmt::format(
        "random {{ seed: {} width_m: 0.04 height_m: 0.02 min_radius_m: 0.8e-3 max_radius_m: "
        "1.0e-3 particle_count: 300 target_porosity: 0.2 }} contact_gap_m: 2e-5",
        seed);
    scenes.push_back(seed % 2 == 0
                         ? FrozenScene(index++, v1::SOLVER_KIND_CRANK_NICOLSON, random, 2, 2e-2)
                         : FrozenScene(index++, v1::SOLVER_KIND_EXPLICIT, random, 0.9, 2e-2));
  }
  for (const int columns : {20, 30, 40, 50}) {
    scenes.push_back(FrozenScene(index++, v1::SOLVER_KIND_STEADY,
                                 Lattice("LATTICE_KIND_SQUARE", columns, 20), 0, 0));
  }
  scenes.push_back(MovingScene(index++, 16, 18, 0.008));
  scenes.push_back(MovingScene(index++, 16, 18, 0.014));
  scenes.push_back(MovingScene(index++, 20, 22, 0.01));
  scenes.push_back(MovingScene(index++, 24, 28, 0.012));
  return scenes;
}

class Chaos : public GrpcSeepdTest {
 protected:
  Chaos() : GrpcSeepdTest("e2e-chaos") {}
};

TEST_F(Chaos, TwentyTwoJobsSurviveSeededSigkillsBitIdentical) {
  const std::vector<v1::Scene> scenes = ChaosScenes();
  ASSERT_GE(scenes.size(), 20u);
  const std::vector<std::string> base = {"--workers", "2", "--threads-per-job", "1"};
  const std::vector<std::string> expected = ReferenceHashes(scenes, base);
  ASSERT_FALSE(HasFailure());

  // Checkpoints every 0.1 s of wall time, so they land at steps nobody chose. Interruptions
  // without progress are what this test makes on purpose: no job may be failed for them.
  std::vector<std::string> flags = base;
  for (const char* flag : {"--checkpoint-interval-s", "0.1", "--max-interruptions", "1000"}) {
    flags.push_back(flag);
  }
  Start("chaos", flags);
  std::vector<std::string> ids;
  for (const auto& s : scenes) ids.push_back(Submit(s));

  const unsigned seed = 20261201;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> delay_ms(250, 1200);
  // Which kill each round makes: at a random moment, or at a crash point's seeded n-th pass.
  // The crash points come early, while most jobs still have work left on any machine.
  const std::vector<std::string> rounds = {"checkpoint-file", "", "final-state", "",
                                           "checkpoint-file", "", "final-state", ""};
  int kills = 0;
  std::map<std::string, int> crash_points_hit;  // by point: rounds whose seepd killed itself
  for (const std::string& point : rounds) {
    if (point.empty()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(rng)));
      stub_.reset();
      EXPECT_EQ(server_.Stop(SIGKILL), 128 + SIGKILL);
      ++kills;
    } else {
      // The seepd of this round kills itself at the point's n-th pass (n seeded); a round whose
      // point is never reached in time ends with a kill from here.
      const int nth =
          std::uniform_int_distribution<int>(1, point == "checkpoint-file" ? 4 : 2)(rng);
      stub_.reset();
      EXPECT_EQ(server_.Stop(SIGKILL), 128 + SIGKILL);
      ++kills;
      std::vector<std::string> armed = flags;
      armed.push_back("--test-crash-at");
      armed.push_back(fmt::format("{}:{}", point, nth));
      Start("chaos", armed);
      int exit_status = -1;
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
      while ((exit_status = server_.PollExit()) < 0 &&
             std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      if (exit_status < 0) {
        exit_status = server_.Stop(SIGKILL);
      } else {
        ++crash_points_hit[point];
      }
      EXPECT_EQ(exit_status, 128 + SIGKILL) << point;
      ++kills;
    }
    Start("chaos", flags);
  }
  ExpectBitIdenticalToUninterrupted(
      ids, expected, "seed " + std::to_string(seed) + ", " + std::to_string(kills) + " kills");
  EXPECT_GE(kills, 5);
  for (const char* point : {"checkpoint-file", "final-state"}) {
    EXPECT_GE(crash_points_hit[point], 1) << point << " was never reached; see chaos.out";
  }
  std::printf("chaos: %d kills, %d at checkpoint-file, %d at final-state (seed %u)\n", kills,
              crash_points_hit["checkpoint-file"], crash_points_hit["final-state"], seed);
  const std::string log = ReadFile(dir_ / "chaos.out");
  EXPECT_NE(log.find("resumed from checkpoint"), std::string::npos);
}

}  // namespace
}  // namespace seep::testing
