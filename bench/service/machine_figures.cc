// The machine, disk and scheduler figures the service benches print first (machine_figures.h).
#include "machine_figures.h"

#include <fcntl.h>
#include <sys/statfs.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <thread>
#include <vector>

#include "service_bench.h"

namespace seep::bench {

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
    const auto t0 = Clock::now();
    const bool ok = ::pwrite(fd, block.data(), block.size(), static_cast<off_t>(i) * 4096) ==
                        static_cast<ssize_t>(block.size()) &&
                    ::fdatasync(fd) == 0;
    if (!ok) break;
    ms.push_back(Millis(t0, Clock::now()));
  }
  ::close(fd);
  std::filesystem::remove(path);
  return {Percentile(ms, 0.5), Percentile(ms, 0.99)};
}

std::pair<double, double> WakeUpLateness() {
  std::vector<double> ms;
  for (int i = 0; i < 200; ++i) {
    const auto t0 = Clock::now();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ms.push_back(Millis(t0, Clock::now()) - 1.0);
  }
  return {Percentile(ms, 0.5), Percentile(ms, 0.99)};
}

void PrintMachineFigures(const std::filesystem::path& dir, const char* build_type,
                         const char* build_id) {
  std::printf("machine: %u hardware threads, %s; load average %s\n",
              std::thread::hardware_concurrency(),
              FirstLineWith("/proc/cpuinfo", "model name").c_str(), LoadAverage().c_str());
  std::printf("build: %s, %s, g++ %s; scratch %s (%s)\n", build_type, build_id, __VERSION__,
              dir.c_str(), FileSystemName(dir));
  const auto [sync_p50, sync_p99] = DurableWriteLatency(dir);
  std::printf(
      "disk: 4 KiB overwrite + fdatasync (a WAL commit) p50 %.2f ms, p99 %.2f ms (n = 100)\n",
      sync_p50, sync_p99);
  const auto [late_p50, late_p99] = WakeUpLateness();
  std::printf("scheduler: wake-up after a 1 ms sleep late by p50 %.2f ms, p99 %.2f ms (n = 200)\n",
              late_p50, late_p99);
}

}  // namespace seep::bench
