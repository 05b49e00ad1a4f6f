// What the parts of seep_service_bench share: timing and percentile helpers, the scenes it runs,
// quiet loggers, and the three measurements of issue 5 (each prints its figures, its goal and
// PASS/MISS, and returns whether the goal was met).
#pragma once

#include <spdlog/logger.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "seep/core/run/simulation.h"
#include "seep/v1/scene.pb.h"

namespace seep::bench {

using Clock = std::chrono::steady_clock;

inline double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}
inline double Millis(Clock::time_point a, Clock::time_point b) { return 1e3 * Seconds(a, b); }

// Nearest-rank percentile (q in [0, 1]) of the samples; 0 for none.
double Percentile(std::vector<double> samples, double q);
double Median(const std::vector<double>& samples);

// "PASS" or "MISS".
const char* Verdict(bool met);

// A logger that drops everything (the bench prints its own lines).
std::shared_ptr<spdlog::logger> QuietLogger(const std::string& name);

// A transient (explicit) permeameter on a side x side rigid square lattice of 1 mm disks: side^2
// disks, about side^2 domains and 2 side^2 pipes. end_time_s is far beyond what a bench runs, so
// the run never finishes on its own.
v1::Scene TransientLatticeScene(std::uint32_t side);
// The same on a columns x rows lattice that ends at end_time_s of simulated time.
v1::Scene TransientLatticeScene(std::uint32_t columns, std::uint32_t rows, double end_time_s);
// A steady 6 x 4 lattice: a job that runs in a few milliseconds.
v1::Scene QuickSteadyScene(const std::string& name);

// Runs `sim` until `max_steps` more steps are done or `max_seconds` of wall time passed,
// calling `at_step_end` (may be empty) after every step. Returns the steps done.
std::uint64_t RunFor(core::Simulation& sim, std::uint64_t max_steps, double max_seconds,
                     const std::function<void(const core::Simulation&)>& at_step_end = {});

struct BenchOptions {
  std::uint32_t lattice_side = 316;  // 99,856 disks
  double run_seconds = 10.0;         // wall time per mode of the empirical overhead run
  double short_interval_s = 1.0;     // checkpoint interval of the empirical run
  double default_interval_s = 30.0;  // seepd --checkpoint-interval-s default
  int queued_jobs = 1000;
  int latency_samples = 300;
  std::filesystem::path dir;  // scratch folder (real disk: fsync must cost what it costs)
  std::string build_id;
};

// 1 and 2 share the 100k-disk job: its store, its checkpoints on disk.
bool CheckpointOverheadAndResume(const BenchOptions& options, bool* resume_met);
// 3.
bool SubmitToRunningLatency(const BenchOptions& options);

}  // namespace seep::bench
