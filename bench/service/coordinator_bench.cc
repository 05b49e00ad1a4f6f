// seep_coordinator_bench: the coordinator bench of issue 18 ("remote workers"), against the real
// seepd and seep-worker binaries on loopback. Prints the figures each part rests on (machine,
// disk, scheduler), then
//   1. coordinator load (coordinator_load.cc): seepd --workers 0 with 10,000 queued jobs and 100
//      simulated workers heartbeating every second; limits seepd CPU <= 5 % of one core and
//      ClaimJob (lease) p99 <= 20 ms;
//   2. sweep throughput (sweep_throughput.cc): a 1,000-job sweep of small scenes drained by
//      seepd's own worker processes (judged), on seepd's threads (--sweep-on threads or all) and
//      by seep-worker processes, taking turns with running the same scenes back to back in
//      process; limit: the median over the trials >= 85 % of the in-process jobs per second;
// each with its figures, limit and PASS/MISS. Exit status 0 when both parts pass.
//
//   seep_coordinator_bench [--part all|load|throughput] [--load-seconds 30] [--workers 100]
//                          [--queued 10000] [--sweep-jobs 1000] [--lanes 2] [--sweep-on both]
//                          [--sweep-columns 40] [--sweep-rows 40] [--sweep-end-time-s 3.1484e-3]
//                          [--sweep-trials 5] [--sweep-slice-s 1] [--dir PATH] [--keep]
#include "coordinator_bench.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "machine_figures.h"
#include "service_bench.h"

int main(int argc, char** argv) {
  seep::bench::CoordinatorOptions options;
  options.dir = std::filesystem::temp_directory_path() /
                ("seep-coordinator-bench-" + std::to_string(::getpid()));
  std::string part = "all";
  CLI::App app{"seep_coordinator_bench: issue 18's coordinator load and sweep throughput"};
  app.add_option("--part", part, "which part to run")
      ->check(CLI::IsMember({"all", "load", "throughput"}))
      ->capture_default_str();
  app.add_option("--queued", options.queued_jobs, "1. jobs queued before the measurement")
      ->check(CLI::Range(1, 10'000))
      ->capture_default_str();
  app.add_option("--workers", options.simulated_workers, "1. simulated workers (threads)")
      ->check(CLI::Range(1, 150))
      ->capture_default_str();
  app.add_option("--heartbeat-s", options.heartbeat_s, "1. seconds between two heartbeats")
      ->check(CLI::Range(0.1, 10.0))
      ->capture_default_str();
  app.add_option("--heartbeats-per-job", options.heartbeats_per_job,
                 "1. heartbeats of a simulated job before it finishes")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--warmup-s", options.warmup_s, "1. seconds before the measured window")
      ->check(CLI::Range(0.0, 600.0))
      ->capture_default_str();
  app.add_option("--load-seconds", options.load_seconds, "1. the measured window, in seconds")
      ->check(CLI::Range(1.0, 3600.0))
      ->capture_default_str();
  app.add_option("--floor-seconds", options.floor_seconds,
                 "1. then seconds of trivial calls at the same rate (gRPC's own cost; 0: none)")
      ->check(CLI::Range(0.0, 600.0))
      ->capture_default_str();
  app.add_option("--sweep-jobs", options.sweep_jobs, "2. jobs of the sweep")
      ->check(CLI::Range(1, 10'000))
      ->capture_default_str();
  app.add_option("--sweep-trials", options.sweep_trials,
                 "2. trials (each a fresh seepd); judged by their median ratio")
      ->check(CLI::Range(1, 99))
      ->capture_default_str();
  app.add_option("--sweep-slice-s", options.sweep_slice_s,
                 "2. seconds of a turn: the service and the in-process run take turns")
      ->check(CLI::Range(0.05, 60.0))
      ->capture_default_str();
  app.add_option("--sweep-on", options.sweep_on,
                 "2. local (seepd's own worker processes), threads (seepd --isolation thread), "
                 "remote (seep-worker processes), both (local and remote) or all")
      ->check(CLI::IsMember({"local", "threads", "remote", "both", "all"}))
      ->capture_default_str();
  app.add_option("--lanes", options.lanes,
                 "2. seep-worker processes (one worker each), and as many in-process lanes")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--sweep-columns", options.sweep_columns, "2. the scene's lattice columns")
      ->check(CLI::Range(2, 2000))
      ->capture_default_str();
  app.add_option("--sweep-rows", options.sweep_rows, "2. the scene's lattice rows")
      ->check(CLI::Range(2, 2000))
      ->capture_default_str();
  app.add_option("--sweep-end-time-s", options.sweep_end_time_s,
                 "2. the scene's simulated seconds (a step is about 2.1 us)")
      ->check(CLI::Range(1e-6, 10.0))
      ->capture_default_str();
  app.add_option("--seepd", options.seepd, "the seepd binary")->capture_default_str();
  app.add_option("--seep-worker", options.seep_worker, "the seep-worker binary")
      ->capture_default_str();
  app.add_option("--dir", options.dir, "scratch folder (on a real disk)");
  app.add_flag("--keep", options.keep, "keep the scratch folder (data folders, logs)");
  CLI11_PARSE(app, argc, argv);
  std::filesystem::create_directories(options.dir);

  std::printf("seep_coordinator_bench: remote workers' coordinator (issue 18)\n");
  seep::bench::PrintMachineFigures(options.dir, SEEP_BUILD_TYPE, SEEP_BUILD_ID);
  const auto start = seep::bench::Clock::now();
  bool met = true;
  if (part != "throughput") met = seep::bench::CoordinatorLoad(options) && met;
  if (part != "load") met = seep::bench::SweepThroughput(options) && met;
  std::printf("\n%s (%.0f s in all; load average at the end %s)\n", seep::bench::Verdict(met),
              seep::bench::Seconds(start, seep::bench::Clock::now()),
              seep::bench::LoadAverage().c_str());
  if (!options.keep) {
    std::error_code ec;
    std::filesystem::remove_all(options.dir, ec);
  }
  return met ? 0 : 1;
}
