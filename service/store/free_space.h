// FreeSpaceGuard: how much room the data folder's file system has left, against the amount seepd
// keeps free (--min-free-disk-mb).
//
// Below it seepd takes on nothing that grows its files: no job is accepted or started, and a
// running job's next checkpoint is not written (the job fails, saying so). What it still writes
// is small and bounded (a job's outcome and events, leases, progress): the reserve is there so
// that those always fit. Every refusal names the free space measured and the flag, so that
// whoever reads it knows what to free or to change.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "seep/core/status.h"

namespace seep::service {

struct FreeSpacePolicy {
  // Bytes kept free on the data folder's file system; 0: nothing is refused for lack of space
  // (a file system that fills up still fails writes, reported as RESOURCE_EXHAUSTED).
  std::uint64_t min_free_bytes = 0;
  // Test only: the free space is read from this file (a number of bytes) instead of the file
  // system, so that a test can make the disk "full" and free it again without filling one.
  std::filesystem::path test_free_bytes_file;
};

// One measurement, and what it means against the policy.
struct FreeSpaceReading {
  std::uint64_t free_bytes = 0;
  std::uint64_t min_free_bytes = 0;
  bool measured = false;  // false: the file system could not be asked (never counted low)
  // Below the threshold once `extra_bytes` more are written.
  bool LowAfter(std::uint64_t extra_bytes) const;
  bool low() const { return LowAfter(0); }
  // "1.2 MiB free on the data folder's file system, less than the 256.0 MiB that
  // --min-free-disk-mb 256 keeps free"
  std::string Describe() const;
  // "1.2 MiB free on the data folder's file system, --min-free-disk-mb 256": the figures alone,
  // for a write the file system itself refused.
  std::string Figures() const;
};

class FreeSpaceGuard {
 public:
  FreeSpaceGuard(std::filesystem::path data_dir, FreeSpacePolicy policy);

  FreeSpaceReading Measure() const;
  bool Low() const { return Measure().low(); }
  // OK while writing `extra_bytes` leaves the threshold free; else RESOURCE_EXHAUSTED
  // "disk full: <the free space and the threshold>: <refused>".
  core::Status CheckRoom(std::string_view refused, std::uint64_t extra_bytes = 0) const;
  const FreeSpacePolicy& policy() const { return policy_; }

 private:
  std::filesystem::path data_dir_;
  FreeSpacePolicy policy_;
};

// What a submit refused for lack of space is told after the figures.
inline constexpr const char* kNoNewJobs = "no job is accepted until space is freed";

// "12.0 MiB", "3.4 GiB", "512 bytes": sizes in the messages above.
std::string HumanBytes(std::uint64_t bytes);

}  // namespace seep::service
