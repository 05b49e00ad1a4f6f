#include "free_space.h"

#include <fmt/format.h>
#include <sys/statvfs.h>

#include <charconv>
#include <fstream>
#include <sstream>

namespace seep::service {

bool FreeSpaceReading::LowAfter(std::uint64_t extra_bytes) const {
  if (!measured || min_free_bytes == 0) return false;
  return free_bytes < min_free_bytes || free_bytes - min_free_bytes < extra_bytes;
}

std::string FreeSpaceReading::Describe() const {
  return fmt::format(
      "{} free on the data folder's file system, less than the {} that "
      "--min-free-disk-mb {} keeps free",
      HumanBytes(free_bytes), HumanBytes(min_free_bytes), min_free_bytes >> 20);
}

std::string FreeSpaceReading::Figures() const {
  if (!measured) return "the free space could not be measured";
  return fmt::format("{} free on the data folder's file system, --min-free-disk-mb {}",
                     HumanBytes(free_bytes), min_free_bytes >> 20);
}

FreeSpaceGuard::FreeSpaceGuard(std::filesystem::path data_dir, FreeSpacePolicy policy)
    : data_dir_(std::move(data_dir)), policy_(std::move(policy)) {}

FreeSpaceReading FreeSpaceGuard::Measure() const {
  FreeSpaceReading reading;
  reading.min_free_bytes = policy_.min_free_bytes;
  if (!policy_.test_free_bytes_file.empty()) {
    std::ifstream in(policy_.test_free_bytes_file);
    std::stringstream text;
    text << in.rdbuf();
    const std::string number = text.str();
    std::uint64_t value = 0;
    const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
    reading.measured = in.good() && error == std::errc() && end != number.data();
    reading.free_bytes = value;
    return reading;
  }
  struct statvfs fs {};
  if (::statvfs(data_dir_.c_str(), &fs) != 0) return reading;
  // What an unprivileged process may still allocate (root's reserved blocks are not seepd's).
  reading.free_bytes = static_cast<std::uint64_t>(fs.f_bavail) * fs.f_frsize;
  reading.measured = true;
  return reading;
}

core::Status FreeSpaceGuard::CheckRoom(std::string_view refused, std::uint64_t extra_bytes) const {
  const FreeSpaceReading reading = Measure();
  if (!reading.LowAfter(extra_bytes)) return core::Status::Ok();
  if (reading.low()) {
    return core::ResourceExhausted(fmt::format("disk full: {}: {}", reading.Describe(), refused));
  }
  return core::ResourceExhausted(fmt::format(
      "disk full: {} free on the data folder's file system; {} more would leave less than the {} "
      "that --min-free-disk-mb {} keeps free: {}",
      HumanBytes(reading.free_bytes), HumanBytes(extra_bytes), HumanBytes(reading.min_free_bytes),
      reading.min_free_bytes >> 20, refused));
}

std::string HumanBytes(std::uint64_t bytes) {
  constexpr const char* kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB"};
  if (bytes < 1024) return fmt::format("{} bytes", bytes);
  double value = static_cast<double>(bytes) / 1024.0;
  std::size_t unit = 0;
  while (value >= 1024.0 && unit + 1 < std::size(kUnits)) {
    value /= 1024.0;
    ++unit;
  }
  return fmt::format("{:.1f} {}", value, kUnits[unit]);
}

}  // namespace seep::service
