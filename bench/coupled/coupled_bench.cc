// seep_coupled_bench (issue 19): the coupled scenes users run, each with its fluid effects and
// again with them off, so that what the fluid costs is measured on the same particles over the
// same number of steps:
//   fracturing xS   examples/hydraulic_fracturing.textproto with its lattice S times wider and
//                   taller (--scales, default 4 and 8: 10,748 and 43,004 disks);
//   consolidation   examples/terzaghi_column.textproto as it is (400 disks, implicit flow).
// "Mechanics" is the same scene without the effects flow, fluid_forces, volume_change,
// aperture_update, redetection and injection, and without the walls' drains: contacts, bonds,
// walls with their servos, damping. Each run takes --warmup steps, then --steps timed steps, on
// each of --threads; with --steps 0 the coupled run goes to the scene's end and the mechanics-only
// one takes as many steps (a whole run: a short window from the start sees no bond break and few
// re-detections). Printed per run: particle-steps/s, the time per effect (the run's own split,
// warm-up included), and the heap the simulation holds per particle (glibc's mallinfo2, in use
// after the warm-up less before Create). Per scene and thread count: the fluid share
// 1 - t_mechanics / t_coupled and the ratio of the rates. Limits (issue 19): every coupled scene
// within 2x of its mechanics-only rate, at most 0.6 kB of heap per particle; the 2/1-thread
// speed-up of the coupled runs is printed beside them.
//
//   seep_coupled_bench [--steps 400 (0: to the end)] [--warmup 100] [--scales 4,8] [--threads 1,2]
//                      [--examples DIR]
#include <fmt/format.h>
#include <malloc.h>
#include <omp.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "codec/scene_codec.h"
#include "scene_file.h"
#include "seep/core/run/simulation.h"
#include "seep/v1/scene.pb.h"

namespace {

using seep::core::Simulation;

constexpr double kMaxSlowdown = 2.0;          // coupled rate >= mechanics rate / 2
constexpr double kMaxBytesPerParticle = 600;  // 0.6 kB

struct Options {
  std::uint64_t steps = 400;
  std::uint64_t warmup = 100;
  std::vector<int> scales = {4, 8};
  std::vector<int> threads = {1, 2};
  std::string examples = SEEP_EXAMPLES_DIR;
};

// The CLI's reader: a bad file is named with its line and column.
std::optional<seep::v1::Scene> LoadScene(const std::string& path) {
  seep::v1::Scene scene;
  if (const std::string error = seep::client::LoadSceneFile(path, &scene); !error.empty()) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return std::nullopt;
  }
  return scene;
}

// The scene without what the fluid adds (see the file comment), on the particles the coupled
// scene starts with: its set-up removes the disks inside a well, which a scene without flow keeps.
std::optional<seep::v1::Scene> MechanicsOnly(const seep::v1::Scene& coupled) {
  auto spec = seep::service::DecodeScene(coupled);
  auto start =
      spec.ok() ? Simulation::Create(*spec) : seep::core::Result<Simulation>(spec.status());
  if (!start.ok()) {
    std::fprintf(stderr, "%s\n", start.status().ToString().c_str());
    return std::nullopt;
  }
  seep::v1::Scene scene = coupled;
  // Stopped by its step count: its own (longer) step must not reach the end time first.
  scene.mutable_solver()->set_end_time_s(1e3 * coupled.solver().end_time_s());
  seep::v1::ParticleList* particles = scene.mutable_packing()->mutable_particles();
  const seep::core::ParticleView view = start->particles();
  particles->mutable_x_m()->Assign(view.x.begin(), view.x.end());
  particles->mutable_y_m()->Assign(view.y.begin(), view.y.end());
  particles->mutable_radius_m()->Assign(view.radius.begin(), view.radius.end());
  scene.clear_effects();
  for (const seep::v1::Effect& effect : coupled.effects()) {
    switch (effect.kind_case()) {
      case seep::v1::Effect::kFlow:
      case seep::v1::Effect::kFluidForces:
      case seep::v1::Effect::kVolumeChange:
      case seep::v1::Effect::kApertureUpdate:
      case seep::v1::Effect::kRedetection:
      case seep::v1::Effect::kInjection:
        continue;
      default:
        break;
    }
    seep::v1::Effect* kept = scene.add_effects();
    *kept = effect;
    if (kept->has_walls()) {
      for (seep::v1::Wall& wall : *kept->mutable_walls()->mutable_walls()) wall.clear_drain();
    }
  }
  return scene;
}

// Heap bytes in use (small blocks and mmapped ones).
double HeapInUse() {
  const struct mallinfo2 info = mallinfo2();
  return static_cast<double>(info.uordblks + info.hblkhd);
}

// Runs `steps` more steps (0: to the scene's end); the wall seconds, or nullopt when the run
// ended otherwise.
std::optional<double> RunSteps(Simulation& sim, std::uint64_t steps) {
  std::stop_source stop;
  seep::core::RunControl control;
  control.stop = stop.get_token();
  if (steps > 0) {
    const std::uint64_t target = sim.step() + steps;
    control.at_step_end = [&stop, target](const Simulation& s) {
      if (s.step() >= target) stop.request_stop();
    };
  }
  const auto t0 = std::chrono::steady_clock::now();
  const seep::core::Status status = sim.Run(control);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto expected =
      steps > 0 ? seep::core::StatusCode::kCancelled : seep::core::StatusCode::kOk;
  if (status.code() != expected) {
    std::fprintf(stderr, "the run ended %s: %s\n", steps > 0 ? "before its steps" : "in error",
                 status.ToString().c_str());
    return std::nullopt;
  }
  return seconds;
}

struct RunFigures {
  double rate = 0.0;  // particle-steps/s over the timed steps
  double seconds = 0.0;
  std::uint64_t steps = 0;  // timed
  double bytes_per_particle = 0.0;
  std::size_t particles = 0;
};

// Timed `steps` (0: to the scene's end) after the warm-up.
std::optional<RunFigures> Measure(const std::string& label, const seep::v1::Scene& scene,
                                  const Options& options, std::uint64_t steps, int threads) {
  omp_set_num_threads(threads);
  auto spec = seep::service::DecodeScene(scene);
  if (!spec.ok()) {
    std::fprintf(stderr, "%s: %s\n", label.c_str(), spec.status().ToString().c_str());
    return std::nullopt;
  }
  const double heap_before = HeapInUse();
  auto sim = Simulation::Create(*spec);
  if (!sim.ok()) {
    std::fprintf(stderr, "%s: %s\n", label.c_str(), sim.status().ToString().c_str());
    return std::nullopt;
  }
  if (options.warmup > 0 && !RunSteps(*sim, options.warmup)) return std::nullopt;
  RunFigures out;
  out.particles = sim->particles().size();
  out.bytes_per_particle = (HeapInUse() - heap_before) / static_cast<double>(out.particles);
  const std::uint64_t first = sim->step();
  const std::optional<double> seconds = RunSteps(*sim, steps);
  if (!seconds) return std::nullopt;
  out.seconds = *seconds;
  out.steps = sim->step() - first;
  out.rate = static_cast<double>(out.particles * out.steps) / *seconds;
  double total = 0.0;
  const auto split = sim->stepper().EffectSeconds();
  for (const auto& [name, t] : split) total += t;
  std::string effects;
  for (const auto& [name, t] : split) {
    effects += fmt::format(" {} {:.1f}%", name, 100.0 * t / total);
  }
  std::printf(
      "  %-13s %d thread(s): %zu disks, dt %.3g s, %llu steps in %.3f s: %.3g "
      "particle-steps/s; heap %.0f B a particle\n",
      label.c_str(), threads, out.particles, sim->dt_s(),
      static_cast<unsigned long long>(out.steps), *seconds, out.rate, out.bytes_per_particle);
  std::printf("    time per effect:%s\n", effects.c_str());
  return out;
}

// One scene, coupled and mechanics-only, on every thread count; true when it meets the limits.
bool BenchScene(const std::string& name, const seep::v1::Scene& coupled, const Options& options) {
  std::printf("\n== %s\n", name.c_str());
  const std::optional<seep::v1::Scene> mechanics = MechanicsOnly(coupled);
  if (!mechanics) return false;
  bool met = true;
  std::map<int, double> coupled_seconds;
  for (const int threads : options.threads) {
    const std::optional<RunFigures> with =
        Measure("coupled", coupled, options, options.steps, threads);
    if (!with) return false;
    if (with->steps == 0) {
      std::fprintf(stderr, "%s: the scene ended within the warm-up\n", name.c_str());
      return false;
    }
    const std::optional<RunFigures> without =
        Measure("mechanics", *mechanics, options, with->steps, threads);
    if (!without) return false;
    coupled_seconds[threads] = with->seconds;
    const double slowdown = without->rate / with->rate;
    const bool fast = slowdown <= kMaxSlowdown;
    const bool small = with->bytes_per_particle <= kMaxBytesPerParticle;
    std::printf(
        "  %d thread(s): fluid share %.1f %%; mechanics / coupled rate %.2fx   %s (limit: <= "
        "%.1fx); coupled heap %.0f B a particle   %s (limit: <= %.0f B)\n",
        threads, 100.0 * (1.0 - without->seconds / with->seconds), slowdown, fast ? "PASS" : "MISS",
        kMaxSlowdown, with->bytes_per_particle, small ? "PASS" : "MISS", kMaxBytesPerParticle);
    met = met && fast && small;
  }
  if (coupled_seconds.contains(1) && coupled_seconds.contains(2)) {
    std::printf("  coupled 2/1-thread speed-up %.2fx\n", coupled_seconds[1] / coupled_seconds[2]);
  }
  return met;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  CLI::App app{"seep_coupled_bench: the coupled scenes users run, with and without the fluid"};
  app.add_option("--steps", options.steps,
                 "timed steps of every run (0: the coupled run to the scene's end, the "
                 "mechanics-only one as many steps)")
      ->check(CLI::Range(0, 100000000));
  app.add_option("--warmup", options.warmup, "steps before the timed ones")
      ->check(CLI::Range(0, 1000000));
  app.add_option("--scales", options.scales, "the fracturing example's lattice scale factors")
      ->delimiter(',')
      ->check(CLI::Range(1, 32));
  app.add_option("--threads", options.threads, "thread counts")
      ->delimiter(',')
      ->check(CLI::Range(1, 256));
  app.add_option("--examples", options.examples, "the examples folder");
  CLI11_PARSE(app, argc, argv);

  const std::optional<seep::v1::Scene> fracturing =
      LoadScene(options.examples + "/hydraulic_fracturing.textproto");
  const std::optional<seep::v1::Scene> column =
      LoadScene(options.examples + "/terzaghi_column.textproto");
  if (!fracturing || !column) return 1;
  const std::string timed =
      options.steps > 0 ? fmt::format("{} timed steps a run", options.steps)
                        : std::string("the coupled run to its end and the mechanics as many steps");
  std::printf("seep_coupled_bench: %llu warm-up steps, then %s\n",
              static_cast<unsigned long long>(options.warmup), timed.c_str());
  bool met = true;
  for (const int scale : options.scales) {
    seep::v1::Scene scene = *fracturing;
    seep::v1::LatticePacking* lattice = scene.mutable_packing()->mutable_lattice();
    lattice->set_columns(lattice->columns() * static_cast<std::uint32_t>(scale));
    lattice->set_rows(lattice->rows() * static_cast<std::uint32_t>(scale));
    met = BenchScene(fmt::format("fracturing x{} ({} x {} lattice)", scale, lattice->columns(),
                                 lattice->rows()),
                     scene, options) &&
          met;
  }
  met = BenchScene("consolidation (the Terzaghi column)", *column, options) && met;
  // The same column with the other factorization a user can choose for it
  // (solver.linear_solver: LINEAR_SOLVER_SIMPLICIAL_LDLT, Eigen's simplicial LDL^T): the example
  // keeps the default, CHOLMOD supernodal. Printed beside the example, not judged: the limits are
  // for the scenes as shipped.
  seep::v1::Scene column_simplicial = *column;
  column_simplicial.mutable_solver()->set_linear_solver(seep::v1::LINEAR_SOLVER_SIMPLICIAL_LDLT);
  BenchScene("consolidation, solver.linear_solver SIMPLICIAL_LDLT (not judged)", column_simplicial,
             options);
  std::printf("\n%s\n", met ? "PASS" : "MISS");
  return met ? 0 : 1;
}
