// Benchmark: rebuilding domains and pipes from contacts (goal from the issue: <= 0.3 us per
// domain at ~1e6 domains), contact detection per particle, and memory per particle.
//
// Usage: seep_domain_rebuild_bench [path/to/settled_bed_9900.txt] [lattice_side]
// Cases: a hex lattice of side^2 disks (row-major ids, i.e. locality-ordered; 2 (side-1)^2
// triangle domains, 1,005,362 for the default side 710), the same lattice with every centre
// jittered by up to 2% of R (irregular angles, about half the contacts overlapping, so lens
// areas are computed), and the shared 9,900-disk settled bed.
// Timings are the best of several repetitions with warm buffers (the steady state of a DEM run
// that re-detects with reused ContactDetector/DomainDetector objects).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bench_beds.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/geometry/packing_file.h"

namespace {

using seep::core::ContactDetector;
using seep::core::ContactList;
using seep::core::DomainDetector;
using seep::core::DomainNetwork;
using seep::core::Packing;

double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

template <typename F>
double BestOf(int repetitions, F&& body) {
  double best = 1e300;
  for (int k = 0; k < repetitions; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    body();
    best = std::min(best, Seconds(std::chrono::steady_clock::now() - t0));
  }
  return best;
}

int Run(const char* name, const Packing& packing, double max_gap, int repetitions) {
  ContactDetector contact_detector;
  ContactList contacts;
  DomainDetector domain_detector;
  DomainNetwork network;
  bool ok = true;
  const double t_contacts = BestOf(
      repetitions, [&] { ok = ok && contact_detector.Detect(packing, max_gap, &contacts).ok(); });
  const double t_domains = BestOf(repetitions, [&] {
    ok = ok && domain_detector.Detect(packing, contacts, {}, &network).ok();
  });
  if (!ok) {
    std::fprintf(stderr, "%s: detection failed\n", name);
    return 1;
  }
  const double n = static_cast<double>(packing.size());
  const double domains = static_cast<double>(network.num_domains());
  const std::size_t bytes = packing.MemoryBytes() + contacts.MemoryBytes() + network.MemoryBytes() +
                            domain_detector.MemoryBytes() + contact_detector.MemoryBytes();
  const std::size_t result_bytes =
      packing.MemoryBytes() + contacts.MemoryBytes() + network.MemoryBytes();
  const bool euler = network.euler.vertices - network.euler.edges + network.euler.cycles ==
                     2 * network.euler.components;
  std::printf("%s\n", name);
  std::printf(
      "  particles %zu, contacts %zu, domains %zu, pipes %zu, boundary pipes %zu, Euler %s\n",
      packing.size(), contacts.size(), network.num_domains(), network.num_pipes(),
      network.num_boundary_pipes(), euler ? "ok" : "FAILED");
  std::printf("  contact detection : %8.2f ms  = %.3f us per particle\n", 1e3 * t_contacts,
              1e6 * t_contacts / n);
  std::printf("  domains + pipes   : %8.2f ms  = %.3f us per domain (goal <= 0.3)\n",
              1e3 * t_domains, 1e6 * t_domains / std::max(domains, 1.0));
  std::printf(
      "  memory            : %.1f bytes per particle incl. workspaces "
      "(%.1f for packing + contacts + network)\n",
      static_cast<double>(bytes) / n, static_cast<double>(result_bytes) / n);
  return euler ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string bed_path =
      argc > 1 ? argv[1] : std::string(SEEP_SHARED_DIR) + "/bench/settled_bed_9900.txt";
  const int side = argc > 2 ? std::atoi(argv[2]) : 710;
  int failures = 0;

  const double R = 0.5;
  const seep::core::Result<Packing> hex = seep::core::HexLattice(side, side, R);
  if (!hex.ok()) {
    std::fprintf(stderr, "%s\n", hex.status().ToString().c_str());
    return 1;
  }
  failures += Run("hex lattice (touching, max_gap 1e-6 R)", *hex, 1e-6 * R, 5);

  const Packing jittered = seep::bench::JitteredHexLattice(*hex, R);
  failures += Run("jittered hex lattice (+-2% R, max_gap 0.06 R)", jittered, 0.06 * R, 5);

  const seep::core::Result<Packing> bed = seep::core::LoadPackingFile(bed_path);
  if (bed.ok()) {
    const double mean = seep::bench::MeanRadius(*bed);
    failures += Run("settled bed 9,900 (max_gap 1e-3 mean R)", *bed, 1e-3 * mean, 50);
  } else {
    std::printf("settled bed skipped: %s\n", bed.status().ToString().c_str());
  }
  return failures == 0 ? 0 : 1;
}
