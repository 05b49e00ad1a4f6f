// Benchmark: the flow's share of a coupled step (docs/performance.md §4, goal G6: aperture update,
// pressure sweep and fluid forces on the disks, flow sub-stepped 1:1 with the DEM), on the shared
// settled bed with the reference DEM settings (kn = 2e6, kt = 2/7 kn, gamma_n = 2000, friction 0.5,
// density 1, gravity 10, dt = 1e-4; side walls instead of the periodic x of the reference, which
// scenes do not offer).
//
// Usage: seep_coupled_share_bench path/to/settled_bed_9900.txt [steps=2000] [flow_every=1]
//                                 [threads: 1 or 2 alone, e.g. for a profile of one of them]
// Runs the bed twice through the scene API, 200 warm-up steps then `steps` timed steps each:
//   mechanics  effects contacts, gravity, walls (bottom, left, right);
//   coupled    the same plus flow (explicit, one flow update per DEM step, or per flow_every
//              steps: volume change, apertures and sweep then run on those steps only),
//              fluid_forces, volume_change and aperture_update, with a fluid soft enough that one
//              explicit sub-step covers the DEM step (the 1:1 of G6).
// and prints both rates and the flow share = 1 - t_mechanics / t_coupled, next to the coupled
// run's own split of its time per effect (fluid effects / all, and G6's terms alone), on 1 and
// then 2 threads, and the 2/1 speed-ups.
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stop_token>
#include <string>
#include <string_view>
#include <vector>

#include "seep/core/geometry/packing_file.h"
#include "seep/core/run/simulation.h"

namespace {

using namespace seep::core;  // NOLINT(google-build-using-namespace): a small program

SceneSpec BedScene(const Packing& bed, bool coupled, std::uint64_t flow_every) {
  SceneSpec s;
  s.name = coupled ? "coupled bed" : "mechanics bed";
  s.packing.source = ParticleListSpec{bed.x, bed.y, bed.radius};
  s.packing.contact_gap_m = 0.01;  // reduced units: a hundredth of a diameter
  s.fluid.viscosity_pa_s = 1.0;
  s.fluid.bulk_modulus_pa = 1e-3;  // soft: neither the DEM step nor the 1:1 sub-step shrink
  s.aperture.residual_aperture_m = 1e-3;
  s.aperture.reference_force_n = 100.0;
  s.aperture.gap_multiplier = 0.5;
  s.boundary.axis = FlowAxis::kX;
  s.boundary.inlet_pressure_pa = 1.0;
  s.solver.kind = SolverKind::kExplicit;
  s.solver.dt_factor = 1.0;
  s.solver.end_time_s = 1.0;  // longer than any run: the bench stops it
  ContactsEffectSpec contacts;
  contacts.law.kn = 2.0e6;
  contacts.law.kt = 2.0 / 7.0 * contacts.law.kn;
  contacts.law.friction = 0.5;
  contacts.law.damping_mode = NormalDampingMode::kPerReducedMass;
  contacts.law.gamma_n = 2000.0;
  contacts.density_kg_m3 = 1.0;
  // dt = safety sqrt(m_min / kn) with m_min = pi 0.4^2: 1e-4 as in the reference settings.
  contacts.dt_safety = 1e-4 / std::sqrt(3.14159265358979 * 0.16 / 2.0e6);
  contacts.skin_m = 0.1;
  WallsEffectSpec walls;
  walls.walls = {SideWall(WallSide::kBottom), SideWall(WallSide::kLeft),
                 SideWall(WallSide::kRight)};
  s.effects = {contacts, GravityEffectSpec{0.0, -10.0}, walls};
  if (coupled) {
    s.effects.push_back(FlowEffectSpec{static_cast<std::uint32_t>(flow_every)});
    s.effects.push_back(FluidForcesEffectSpec{});
    s.effects.push_back(VolumeChangeEffectSpec{});
    s.effects.push_back(ApertureUpdateEffectSpec{});
  }
  return s;
}

// The effects G6 counts as flow: what the coupling adds to a mechanics step.
bool IsFluidEffect(std::string_view name) {
  return name == "flow" || name == "fluid_forces" || name == "volume_change" ||
         name == "aperture_update";
}

// Runs `steps` more steps; returns the wall seconds.
double RunSteps(Simulation& sim, std::uint64_t steps) {
  std::stop_source stop;
  RunControl control;
  control.stop = stop.get_token();
  const std::uint64_t target = sim.step() + steps;
  control.at_step_end = [&](const Simulation& s) {
    if (s.step() >= target) stop.request_stop();
  };
  const auto t0 = std::chrono::steady_clock::now();
  const Status status = sim.Run(control);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (status.code() != StatusCode::kCancelled) {
    std::fprintf(stderr, "run ended early: %s\n", status.message().c_str());
    std::exit(1);
  }
  return seconds;
}

struct Shares {
  double seconds[2] = {0.0, 0.0};  // mechanics, coupled: the timed steps
  double fluid = 0.0;              // fluid effects / all, from the coupled run's own split
  double g6 = 0.0;                 // G6's terms (apertures, sweep, fluid forces) / all
  double fluid_ns = 0.0;           // fluid effects per particle-step
};

// Runs the mechanics and the coupled bed on `threads` threads and prints what each costs.
Shares Measure(const Packing& bed, std::uint64_t steps, std::uint64_t flow_every, int threads) {
  omp_set_num_threads(threads);
  Shares out;
  for (int coupled = 0; coupled < 2; ++coupled) {
    Result<Simulation> sim = Simulation::Create(BedScene(bed, coupled == 1, flow_every));
    if (!sim.ok()) {
      std::fprintf(stderr, "%s\n", sim.status().message().c_str());
      std::exit(1);
    }
    RunSteps(*sim, 200);
    // The timed steps in kWindows windows: the run's time is their sum; per effect, the fastest
    // window's time, which a busy neighbour on the machine does not reach as easily as the sum.
    constexpr std::uint64_t kWindows = 40;
    auto before = sim->stepper().EffectSeconds();
    std::vector<double> fastest(before.size(), std::numeric_limits<double>::infinity());
    out.seconds[coupled] = 0.0;
    for (std::uint64_t w = 0; w < kWindows; ++w) {
      const std::uint64_t window = steps / kWindows + (w < steps % kWindows ? 1 : 0);
      if (window == 0) continue;
      out.seconds[coupled] += RunSteps(*sim, window);
      const auto after = sim->stepper().EffectSeconds();
      for (std::size_t k = 0; k < after.size(); ++k) {
        fastest[k] = std::min(fastest[k], (after[k].second - before[k].second) / window);
      }
      before = after;
    }
    const double rate = static_cast<double>(bed.size() * steps) / out.seconds[coupled];
    std::printf("%-9s %d thread(s), %zu disks, dt %.3g, %llu steps: %.3f s, %.3g particle-steps/s",
                coupled ? "coupled" : "mechanics", threads, bed.size(), sim->dt_s(),
                static_cast<unsigned long long>(steps), out.seconds[coupled], rate);
    if (coupled == 1) {
      const LiveState& state = sim->stepper().state();
      std::printf(" (%zu domains, %zu pipes, flow every %llu step(s), %lld sub-step(s) per update)",
                  state.net.domains.num_domains(), state.net.flow.num_pipes(),
                  static_cast<unsigned long long>(sim->stepper().flow_every()),
                  static_cast<long long>(sim->stepper().Measure().at("flow_sub_steps_max")));
    }
    std::printf("\n");
    // Per effect, over the whole run (warm-up included): the run's own split, which does not
    // depend on how loaded the machine was between the two runs.
    double total = 0.0, fluid = 0.0, g6 = 0.0;
    const auto split = sim->stepper().EffectSeconds();
    for (const auto& [name, t] : split) {
      total += t;
      if (IsFluidEffect(name)) fluid += t;
      if (IsFluidEffect(name) && name != "volume_change") g6 += t;
    }
    std::printf("  time per effect:");
    for (const auto& [name, t] : split) {
      std::printf(" %.*s %.1f%%", static_cast<int>(name.size()), name.data(), 100.0 * t / total);
    }
    std::printf("\n  per step, fastest of %llu windows:",
                static_cast<unsigned long long>(kWindows));
    for (std::size_t k = 0; k < split.size(); ++k) {
      std::printf(" %.*s %.0f us", static_cast<int>(split[k].first.size()), split[k].first.data(),
                  1e6 * fastest[k]);
    }
    std::printf("\n");
    if (coupled == 1) {
      out.fluid = fluid / total;
      out.g6 = g6 / total;
      out.fluid_ns = 1e9 * fluid / static_cast<double>(bed.size() * (steps + 200));
    }
  }
  const double share = 1.0 - out.seconds[0] / out.seconds[1];
  std::printf(
      "  %d thread(s): flow share of a coupled step %.1f %% from the two runs, %.1f %% from the "
      "coupled run's own split (%.1f ns per particle-step); G6's terms alone (apertures, sweep, "
      "fluid forces; volume change not counted) %.1f %%\n",
      threads, 100.0 * share, 100.0 * out.fluid, out.fluid_ns, 100.0 * out.g6);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s settled_bed_9900.txt [steps=2000] [flow_every=1] [threads]\n",
                 argv[0]);
    return 2;
  }
  const std::uint64_t steps = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 2000;
  const std::uint64_t flow_every = argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 1;
  const long only_threads = argc > 4 ? std::strtol(argv[4], nullptr, 10) : 0;
  if (steps < 1 || flow_every < 1 || flow_every > UINT32_MAX) {
    std::fprintf(stderr, "steps must be >= 1 and flow_every in [1, 2^32)\n");
    return 2;
  }
  if (argc > 4 && only_threads != 1 && only_threads != 2) {
    std::fprintf(stderr, "threads: 1 or 2 (got '%s')\n", argv[4]);
    return 2;
  }
  Result<Packing> bed = LoadPackingFile(argv[1]);
  if (!bed.ok()) {
    std::fprintf(stderr, "%s\n", bed.status().message().c_str());
    return 1;
  }
  if (only_threads != 0) {
    Measure(*bed, steps, flow_every, static_cast<int>(only_threads));
    return 0;
  }
  const Shares one = Measure(*bed, steps, flow_every, 1);
  const Shares two = Measure(*bed, steps, flow_every, 2);
  std::printf(
      "2/1 thread speed-up: mechanics %.2fx, coupled %.2fx (goals: G6 flow share <= 25 %%, "
      "issue #4 and G6 stretch <= 10 %%)\n",
      one.seconds[0] / two.seconds[0], one.seconds[1] / two.seconds[1]);
  return 0;
}
