// What the service benches' figures rest on, printed before them: the machine, the file system
// and disk under the scratch folder (a durable write is what every store commit costs), and how
// late the scheduler wakes a thread.
#pragma once

#include <filesystem>
#include <string>
#include <utility>

namespace seep::bench {

// The rest of the first line of `path` that starts with `prefix`, after its ": "; "?" if none.
std::string FirstLineWith(const char* path, const std::string& prefix);
// The 1, 5 and 15 minute load averages, as /proc/loadavg gives them.
std::string LoadAverage();
// ext4, xfs, ... of the file system holding `dir`; tmpfs is named as too good to be true.
const char* FileSystemName(const std::filesystem::path& dir);
// One durable 4 KiB overwrite (pwrite + fdatasync, as a SQLite WAL commit) in `dir`: {p50, p99}
// in ms over 100.
std::pair<double, double> DurableWriteLatency(const std::filesystem::path& dir);
// How late a thread runs after a 1 ms sleep (the delay any woken thread pays right now): {p50,
// p99} in ms over 200.
std::pair<double, double> WakeUpLateness();
// Prints the machine, disk and scheduler lines (one each) for the scratch folder `dir`.
void PrintMachineFigures(const std::filesystem::path& dir, const char* build_type,
                         const char* build_id);

}  // namespace seep::bench
