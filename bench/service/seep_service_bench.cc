// The durable-service figures of issue 5, with their goals and PASS/MISS. Prints numbers; asserts
// nothing about speed.
//
//   seep_service_bench [side=316] [run_s=10] [interval_s=1] [queued=1000] [samples=300]
//                      [dir=./seep-service-bench-<pid>] [keep=0]
//
// 1. Checkpoint overhead at seepd's default interval (30 s) on a side x side disk lattice run by
//    the explicit solver: one checkpoint's wall cost over the interval, and a measured run with
//    checkpoints off against one every interval_s seconds (run_s seconds per mode).
// 2. Time to resume that job from its newest checkpoint on disk to a Simulation ready to step.
// 3. Submit-to-running latency with `queued` jobs QUEUED, over `samples` samples
//    (submit_latency.cc has the definition).
// Scratch files go to `dir` (on a real disk: fsync must cost what it costs), removed at the end
// unless keep=1.
#include <unistd.h>

#include <cstdio>
#include <string>

#include "machine_figures.h"
#include "service_bench.h"

#ifndef SEEP_BUILD_ID
#define SEEP_BUILD_ID "unknown"
#endif
#ifndef SEEP_BUILD_TYPE
#define SEEP_BUILD_TYPE "unknown"
#endif

int main(int argc, char** argv) {
  seep::bench::BenchOptions options;
  bool keep = false;
  options.dir =
      std::filesystem::current_path() / ("seep-service-bench-" + std::to_string(getpid()));
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto eq = arg.find('=');
    const std::string key = arg.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : arg.substr(eq + 1);
    if (key == "side") {
      options.lattice_side = static_cast<std::uint32_t>(std::stoul(value));
    } else if (key == "run_s") {
      options.run_seconds = std::stod(value);
    } else if (key == "interval_s") {
      options.short_interval_s = std::stod(value);
    } else if (key == "queued") {
      options.queued_jobs = std::stoi(value);
    } else if (key == "samples") {
      options.latency_samples = std::stoi(value);
    } else if (key == "dir") {
      options.dir = value;
    } else if (key == "keep") {
      keep = value == "1";
    } else {
      std::fprintf(stderr,
                   "usage: %s [side=316] [run_s=10] [interval_s=1] [queued=1000] [samples=300] "
                   "[dir=PATH] [keep=0]\n",
                   argv[0]);
      return 2;
    }
  }
  options.build_id = SEEP_BUILD_ID;
  std::filesystem::create_directories(options.dir);

  std::printf("seep_service_bench: durable-service figures (issue 5)\n");
  seep::bench::PrintMachineFigures(options.dir, SEEP_BUILD_TYPE, SEEP_BUILD_ID);

  bool resume_met = false;
  const bool overhead_met = seep::bench::CheckpointOverheadAndResume(options, &resume_met);
  const bool latency_met = seep::bench::SubmitToRunningLatency(options);

  std::printf(
      "\nsummary: checkpoint overhead %s, resume time %s, submit-to-running p99 (worst case) %s\n",
      seep::bench::Verdict(overhead_met), seep::bench::Verdict(resume_met),
      seep::bench::Verdict(latency_met));
  std::printf("load average at the end %s\n", seep::bench::LoadAverage().c_str());
  if (!keep) {
    std::error_code ec;
    std::filesystem::remove_all(options.dir, ec);
  }
  return 0;
}
