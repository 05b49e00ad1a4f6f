// Benchmark: throughput of the DEM mechanics on the settled bed, with the reference settings of
// bench/README.md (linear spring kn = 2e6, kt = 2/7 kn with shear history, gamma_n = 2000,
// friction 0.5, floor at y = 0, periodic x, gravity 10 down, dt = 1e-4, velocity-Verlet,
// density 1), compared with the LAMMPS figures of docs/performance.md §1.3.
//
// Usage: seep_dem_bench path/to/settled_bed_9900.txt [replication_along_x=1] [steps=2000]
//                       [skin=0.1] [threads=12: "1", "2" or "12" for both]
// For each thread count (1, then 2) the bed is rebuilt from the file, run 200 warm-up steps, then
// `steps` timed steps; it prints particle-steps/s, the 2/1 speed-up and the ratio to LAMMPS.
#include <omp.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "seep/core/dem/dem_contacts.h"
#include "seep/core/dem/dem_particles.h"
#include "seep/core/dem/dem_step.h"
#include "seep/core/dem/dem_wall.h"
#include "seep/core/geometry/packing_file.h"

namespace {

using namespace seep::core;  // NOLINT(google-build-using-namespace): a small program

struct RunResult {
  double rate = 0.0;      // particle-steps per wall second
  double cpu_rate = 0.0;  // particle-steps per CPU second of the process (all threads)
  double kinetic = 0.0;
  std::size_t contacts = 0;
  std::size_t pairs = 0;
  DemCounters counters;
  std::size_t state_bytes = 0;
};

// CPU time of the process: on a shared machine it shows what the run would take unloaded
// (1 thread), next to the wall-clock figure the goals are written in.
double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

Result<RunResult> Run(const Packing& packing, double lx, int threads, int steps, double skin) {
  omp_set_num_threads(threads);
  SEEP_ASSIGN_OR_RETURN(DemParticles particles, MakeDemParticles(packing, 1.0));
  DemContactSettings settings;
  settings.law.kn = 2.0e6;
  settings.law.kt = 2.0 / 7.0 * settings.law.kn;
  settings.law.friction = 0.5;
  settings.law.gamma_n = 2000.0;
  settings.skin = skin;
  settings.periodic_x = true;
  settings.x0 = 0.0;
  settings.lx = lx;
  SEEP_ASSIGN_OR_RETURN(DemContactForces contacts, DemContactForces::Create(settings));
  SEEP_ASSIGN_OR_RETURN(DemWall floor, MakeWall(0.0, 0.0, 0.0, 1.0));
  std::vector<DemWall> walls{floor};
  DemStepOptions options;
  options.dt = 1e-4;
  options.gravity_y = -10.0;
  DemCounters counters;
  SEEP_RETURN_IF_ERROR(ComputeDemForces(&particles, walls, &contacts, options, &counters));
  for (int s = 0; s < 200; ++s) {
    SEEP_RETURN_IF_ERROR(DemStep(&particles, &walls, &contacts, options, &counters));
  }
  RunResult r;
  counters = DemCounters{};
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = CpuSeconds();
  for (int s = 0; s < steps; ++s) {
    SEEP_RETURN_IF_ERROR(DemStep(&particles, &walls, &contacts, options, &counters));
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu_seconds = CpuSeconds() - cpu0;
  r.rate = static_cast<double>(particles.size()) * steps / seconds;
  r.cpu_rate = static_cast<double>(particles.size()) * steps / cpu_seconds;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    r.kinetic += 0.5 * particles.mass[i] *
                 (particles.vx[i] * particles.vx[i] + particles.vy[i] * particles.vy[i]);
  }
  std::vector<DemContactRecord> records;
  contacts.CollectContacts(&records);
  r.contacts = records.size();
  r.pairs = contacts.pair_count();
  r.counters = counters;
  r.state_bytes = particles.MemoryBytes() + contacts.MemoryBytes();
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: %s settled_bed_9900.txt [replication_along_x=1] [steps=2000] "
                 "[skin=0.1] [threads=12]\n",
                 argv[0]);
    return 2;
  }
  const int replicate = argc > 2 ? std::atoi(argv[2]) : 1;
  const int steps = argc > 3 ? std::atoi(argv[3]) : 2000;
  const double skin = argc > 4 ? std::atof(argv[4]) : 0.1;
  const std::string which = argc > 5 ? argv[5] : "12";
  std::vector<int> thread_counts;
  if (which.find('1') != std::string::npos) thread_counts.push_back(1);
  if (which.find('2') != std::string::npos) thread_counts.push_back(2);
  if (replicate < 1 || steps < 1 || !(skin >= 0.0)) {
    std::fprintf(stderr, "bad arguments\n");
    return 2;
  }
  Result<Packing> bed = LoadPackingFile(argv[1]);
  if (!bed.ok()) {
    std::fprintf(stderr, "%s\n", bed.status().ToString().c_str());
    return 1;
  }
  // Replicate the 100-wide periodic bed along x (the 99,000-disk case of bench/README.md).
  Packing packing;
  packing.Reserve(bed->size() * static_cast<std::size_t>(replicate));
  for (int c = 0; c < replicate; ++c) {
    for (std::size_t i = 0; i < bed->size(); ++i) {
      packing.Add(bed->x[i] + 100.0 * c, bed->y[i], bed->radius[i]);
    }
  }
  const double lx = 100.0 * replicate;
  std::printf(
      "dem bench: %zu disks, box x [0, %.0f] periodic, %d timed steps after 200 warm-up, "
      "skin %.3g\n",
      packing.size(), lx, steps, skin);
  // LAMMPS 1-core figures (docs/performance.md §1.3): 1.09e7-1.20e7 at 9,900; 8.79e6 at 99,000.
  // Hosts differ by up to 2x: the ratio worth quoting comes from bench/dem/lammps/run_all.sh,
  // which runs both in one session.
  const bool large = packing.size() > 50000;
  const double lammps_lo = large ? 8.79e6 : 1.09e7;
  const double lammps_hi = large ? 8.79e6 : 1.20e7;
  std::printf(
      "(LAMMPS ratios below are to performance.md §1.3; bench/dem/lammps/run_all.sh "
      "measures LAMMPS in the same session)\n");
  double rate1 = 0.0;
  for (int threads : thread_counts) {
    Result<RunResult> r = Run(packing, lx, threads, steps, skin);
    if (!r.ok()) {
      std::fprintf(stderr, "%s\n", r.status().ToString().c_str());
      return 1;
    }
    if (threads == 1) rate1 = r->rate;
    std::printf(
        "threads %d: %.3e particle-steps/s (%.1f ns/particle-step), vs LAMMPS 1 core %.2fx-%.2fx",
        threads, r->rate, 1e9 / r->rate, r->rate / lammps_hi, r->rate / lammps_lo);
    if (threads == 2 && rate1 > 0.0) std::printf(", speed-up 2/1 = %.2fx", r->rate / rate1);
    std::printf("\n  per CPU-second of the process: %.3e particle-steps (%.1f ns)\n", r->cpu_rate,
                1e9 / r->cpu_rate);
    std::printf(
        "  contacts %zu (coordination %.2f), neighbour pairs %zu (%.2f per disk), rebuilds %llu, "
        "kinetic energy %.3e, state %.0f bytes/disk\n",
        r->contacts, 2.0 * r->contacts / packing.size(), r->pairs,
        static_cast<double>(r->pairs) / packing.size(),
        static_cast<unsigned long long>(r->counters.neighbour_rebuilds), r->kinetic,
        static_cast<double>(r->state_bytes) / packing.size());
  }
  return 0;
}
