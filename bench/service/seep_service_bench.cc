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
#include <fcntl.h>
#include <sys/statfs.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "service_bench.h"

#ifndef SEEP_BUILD_ID
#define SEEP_BUILD_ID "unknown"
#endif
#ifndef SEEP_BUILD_TYPE
#define SEEP_BUILD_TYPE "unknown"
#endif

namespace {

std::string FirstLineWith(const char* path, const std::string& prefix) {
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(prefix, 0) == 0) {
      const auto colon = line.find(':');
      return colon == std::string::npos ? line : line.substr(colon + 2);
    }
  }
  return "?";
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  in >> one >> five >> fifteen;
  return one + " " + five + " " + fifteen;
}

const char* FileSystemName(const std::filesystem::path& dir) {
  struct statfs fs {};
  if (::statfs(dir.c_str(), &fs) != 0) return "?";
  switch (static_cast<unsigned long>(fs.f_type)) {
    case 0xEF53:
      return "ext4";
    case 0x58465342:
      return "xfs";
    case 0x9123683E:
      return "btrfs";
    case 0x01021994:
      return "tmpfs (fsync is free: figures are too good)";
    case 0x794C7630:
      return "overlayfs";
    default:
      return "other";
  }
}

// What the disk under `dir` takes for one durable 4 KiB overwrite (pwrite + fdatasync, as a
// SQLite WAL commit): every figure below rests on it. Returns {p50, p99} in ms.
std::pair<double, double> DurableWriteLatency(const std::filesystem::path& dir) {
  const std::string path = (dir / "fsync-probe.bin").string();
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  if (fd < 0) return {0.0, 0.0};
  const std::string block(4096, 'x');
  // Allocated first: a WAL commit mostly overwrites blocks of a file that keeps its size.
  for (int i = 0; i < 100; ++i) {
    if (::pwrite(fd, block.data(), block.size(), static_cast<off_t>(i) * 4096) < 0) break;
  }
  (void)::fsync(fd);
  std::vector<double> ms;
  for (int i = 0; i < 100; ++i) {
    const auto t0 = seep::bench::Clock::now();
    const bool ok = ::pwrite(fd, block.data(), block.size(), static_cast<off_t>(i) * 4096) ==
                        static_cast<ssize_t>(block.size()) &&
                    ::fdatasync(fd) == 0;
    if (!ok) break;
    ms.push_back(seep::bench::Millis(t0, seep::bench::Clock::now()));
  }
  ::close(fd);
  std::filesystem::remove(path);
  return {seep::bench::Percentile(ms, 0.5), seep::bench::Percentile(ms, 0.99)};
}

// How late a thread runs after a 1 ms sleep: the scheduling delay any woken thread (a gRPC
// handler, the worker) pays on this machine right now. Returns {p50, p99} in ms.
std::pair<double, double> WakeUpLateness() {
  std::vector<double> ms;
  for (int i = 0; i < 200; ++i) {
    const auto t0 = seep::bench::Clock::now();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ms.push_back(seep::bench::Millis(t0, seep::bench::Clock::now()) - 1.0);
  }
  return {seep::bench::Percentile(ms, 0.5), seep::bench::Percentile(ms, 0.99)};
}

}  // namespace

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
  std::printf("machine: %u hardware threads, %s; load average %s\n",
              std::thread::hardware_concurrency(),
              FirstLineWith("/proc/cpuinfo", "model name").c_str(), LoadAverage().c_str());
  std::printf("build: %s, %s, g++ %s; scratch %s (%s)\n", SEEP_BUILD_TYPE, SEEP_BUILD_ID,
              __VERSION__, options.dir.c_str(), FileSystemName(options.dir));
  const auto [sync_p50, sync_p99] = DurableWriteLatency(options.dir);
  std::printf(
      "disk: 4 KiB overwrite + fdatasync (a WAL commit) p50 %.2f ms, p99 %.2f ms (n = 100)\n",
      sync_p50, sync_p99);
  const auto [late_p50, late_p99] = WakeUpLateness();
  std::printf("scheduler: wake-up after a 1 ms sleep late by p50 %.2f ms, p99 %.2f ms (n = 200)\n",
              late_p50, late_p99);

  bool resume_met = false;
  const bool overhead_met = seep::bench::CheckpointOverheadAndResume(options, &resume_met);
  const bool latency_met = seep::bench::SubmitToRunningLatency(options);

  std::printf(
      "\nsummary: checkpoint overhead %s, resume time %s, submit-to-running p99 (worst case) %s\n",
      seep::bench::Verdict(overhead_met), seep::bench::Verdict(resume_met),
      seep::bench::Verdict(latency_met));
  std::printf("load average at the end %s\n", LoadAverage().c_str());
  if (!keep) {
    std::error_code ec;
    std::filesystem::remove_all(options.dir, ec);
  }
  return 0;
}
