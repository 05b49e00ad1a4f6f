// Benchmark: local re-detection of one broken (and one re-formed) contact, against a full
// re-detection of the same network measured in the same run. Issue 19's limit: one broken bond in
// a network of about 1e6 domains re-detected in <= 50 us.
//
// Usage: seep_local_redetection_bench [path/to/settled_bed_9900.txt] [lattice_side] [changes]
// Cases: the jittered hex lattice of domain_rebuild_bench (side 710: 1,005,362 triangle domains;
// centres moved by up to 2% of R, so angles are irregular and half the contacts overlap), and the
// shared 9,900-disk settled bed (rattlers, an irregular hull) when it is there.
// Each change breaks one random contact of the intact network and forms it again; each of the two
// updates is timed on its own. At the end the patched network is compared, field by field, with a
// full re-detection (the test suite does this after every change on random sequences).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bench_beds.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/local_domain_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/geometry/packing_file.h"
#include "seep/core/geometry/random_packing.h"

namespace {

using seep::core::ContactDetector;
using seep::core::ContactList;
using seep::core::DomainDetector;
using seep::core::DomainNetwork;
using seep::core::LocalDomainDetector;
using seep::core::Packing;

constexpr double kLimitMicroseconds = 50.0;

double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

double Quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const std::size_t k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}

struct Timings {
  std::vector<double> seconds;
  int local = 0;
  int full = 0;
};

void Count(const LocalDomainDetector& detector, Timings* t) {
  switch (detector.last_update()) {
    case LocalDomainDetector::Update::kLocal:
      ++t->local;
      break;
    case LocalDomainDetector::Update::kFull:
      ++t->full;
      break;
    case LocalDomainDetector::Update::kContactListOnly:
      break;
  }
}

void Print(const char* what, const Timings& t, double full_seconds) {
  const double median = Quantile(t.seconds, 0.5);
  std::printf(
      "  %-8s: median %7.2f us, p99 %8.2f us, max %8.2f us; %d local, %d full; median is "
      "%.0fx faster than a full re-detection\n",
      what, 1e6 * median, 1e6 * Quantile(t.seconds, 0.99),
      1e6 * *std::max_element(t.seconds.begin(), t.seconds.end()), t.local, t.full,
      full_seconds / median);
}

int Run(const char* name, const Packing& packing, double max_gap, int changes) {
  ContactDetector contact_detector;
  ContactList contacts;
  if (!contact_detector.Detect(packing, max_gap, &contacts).ok()) return 1;
  DomainDetector domain_detector;
  DomainNetwork full;
  double full_seconds = 1e300;
  for (int k = 0; k < 3; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!domain_detector.Detect(packing, contacts, {max_gap}, &full).ok()) return 1;
    full_seconds = std::min(full_seconds, Seconds(std::chrono::steady_clock::now() - t0));
  }
  LocalDomainDetector local;
  const auto t0 = std::chrono::steady_clock::now();
  if (!local.Reset(packing, contacts, {max_gap}).ok()) return 1;
  const double reset_seconds = Seconds(std::chrono::steady_clock::now() - t0);

  std::mt19937_64 rng(11);
  Timings breaks;
  Timings forms;
  for (int k = 0; k < changes; ++k) {
    const std::size_t c = static_cast<std::size_t>(seep::core::UniformUnit(rng()) *
                                                   static_cast<double>(contacts.size()));
    const auto a = std::chrono::steady_clock::now();
    const bool removed = local.RemoveContact(contacts.i[c], contacts.j[c]).ok();
    const auto b = std::chrono::steady_clock::now();
    Count(local, &breaks);
    const bool added = local.AddContact(contacts.i[c], contacts.j[c], contacts.gap[c]).ok();
    const auto e = std::chrono::steady_clock::now();
    Count(local, &forms);
    if (!removed || !added) return 1;
    breaks.seconds.push_back(Seconds(b - a));
    forms.seconds.push_back(Seconds(e - b));
  }
  DomainNetwork patched;
  local.Emit(&patched);
  const bool identical = full == patched;  // every field, doubles compared exactly

  std::printf("%s\n", name);
  std::printf(
      "  particles %zu, contacts %zu, domains %zu; local detector %.1f bytes per particle\n",
      packing.size(), contacts.size(), full.num_domains(),
      static_cast<double>(local.MemoryBytes()) / static_cast<double>(packing.size()));
  std::printf("  full re-detection (DomainDetector, best of 3): %.2f ms; Reset %.2f ms\n",
              1e3 * full_seconds, 1e3 * reset_seconds);
  Print("break", breaks, full_seconds);
  Print("re-form", forms, full_seconds);
  const double p99 = 1e6 * Quantile(breaks.seconds, 0.99);
  std::printf(
      "  one broken contact, p99 %.2f us (limit %.0f us): %s; network after %d changes %s\n", p99,
      kLimitMicroseconds, p99 <= kLimitMicroseconds ? "PASS" : "MISS", changes,
      identical ? "identical to a full re-detection" : "DIFFERS from a full re-detection");
  return identical ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string bed_path =
      argc > 1 ? argv[1] : std::string(SEEP_SHARED_DIR) + "/bench/settled_bed_9900.txt";
  const int side = argc > 2 ? std::atoi(argv[2]) : 710;
  const int changes = argc > 3 ? std::atoi(argv[3]) : 2000;
  int failures = 0;

  const double R = 0.5;
  const seep::core::Result<Packing> hex = seep::core::HexLattice(side, side, R);
  if (!hex.ok()) {
    std::fprintf(stderr, "%s\n", hex.status().ToString().c_str());
    return 1;
  }
  const Packing jittered = seep::bench::JitteredHexLattice(*hex, R);
  failures += Run("jittered hex lattice (+-2% R, max_gap 0.06 R)", jittered, 0.06 * R, changes);

  const seep::core::Result<Packing> bed = seep::core::LoadPackingFile(bed_path);
  if (bed.ok()) {
    const double mean = seep::bench::MeanRadius(*bed);
    failures += Run("settled bed 9,900 (max_gap 1e-3 mean R)", *bed, 1e-3 * mean, changes);
  } else {
    std::printf("settled bed skipped: %s\n", bed.status().ToString().c_str());
  }
  return failures == 0 ? 0 : 1;
}
