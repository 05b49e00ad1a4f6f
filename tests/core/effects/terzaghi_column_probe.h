// Measurements on a walled consolidation column (a DEM column between walls that bound the
// fluid: impermeable base and sides, a drained servo top platen), shared by the V17 test and the
// staged examples' tests: samples of the settlement, the mean pore pressure and the platen's
// stress over a run, isochrones (pressure against depth), and the column's own permeability.
#pragma once

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/run/simulation.h"

namespace seep::core::terzaghi_probe {

constexpr std::size_t kBottomWall = 0;  // the walls' order: bottom, left, right, top
constexpr std::size_t kLeftWall = 1;
constexpr std::size_t kRightWall = 2;
constexpr std::size_t kTopWall = 3;

struct Sample {
  double t = 0.0;
  double settlement = 0.0;     // top wall displacement from its set-up position, m (down > 0)
  double mean_pressure = 0.0;  // pore-volume weighted mean over the domains, Pa
  double top_stress = 0.0;     // total normal stress on the top platen, Pa
};

// Pressure against depth below the top platen at one moment: pore-volume weighted band means.
struct Isochrone {
  double t = 0.0;
  std::vector<double> depth, pressure;  // m, Pa
};

constexpr int kBands = 8;

inline Isochrone MeasureIsochrone(const Simulation& now) {
  const LiveState& s = now.stepper().state();
  const double top = s.walls[kTopWall].py;
  const double height = top - s.walls[kBottomWall].py;
  std::vector<double> volume(kBands, 0.0), depth(kBands, 0.0), pressure(kBands, 0.0);
  const auto p = s.net.flow.pressure();
  const auto vp = s.net.flow.pore_volume();
  for (std::size_t d = 0; d < s.net.domains.num_domains(); ++d) {
    const double z = top - s.net.domains.centroid_y[d];
    const int band = std::clamp(static_cast<int>(z / height * kBands), 0, kBands - 1);
    volume[band] += vp[d];
    depth[band] += vp[d] * z;
    pressure[band] += vp[d] * p[d];
  }
  Isochrone out;
  out.t = now.time_s();
  for (int b = 0; b < kBands; ++b) {
    if (volume[b] <= 0.0) continue;
    out.depth.push_back(depth[b] / volume[b]);
    out.pressure.push_back(pressure[b] / volume[b]);
  }
  return out;
}

// Runs `scene` to its end, sampling every `every` steps (and the first and last state), with an
// isochrone at each sample when asked.
inline std::vector<Sample> RunAndSample(const SceneSpec& scene, std::uint64_t every,
                                        std::vector<Isochrone>* isochrones = nullptr) {
  std::vector<Sample> samples;
  Result<Simulation> created = Simulation::Create(scene);
  EXPECT_TRUE(created.ok()) << created.status().message();
  if (!created.ok()) return samples;
  Simulation& sim = *created;
  const double wall0 = sim.stepper().state().walls[kTopWall].py;
  auto record = [&](const Simulation& now) {
    const LiveState& s = now.stepper().state();
    Sample sample;
    sample.t = now.time_s();
    sample.settlement = wall0 - s.walls[kTopWall].py;
    if (s.has_network) {
      sample.mean_pressure = VolumeWeightedMeanPressure(s.net.flow, StorageVolume::kPore);
    }
    if (s.moves()) {
      const double width = s.walls[kRightWall].px - s.walls[kLeftWall].px;
      const double pore = s.wall_pore_force.empty() ? 0.0 : s.wall_pore_force[kTopWall];
      sample.top_stress = (s.contacts->wall_loads()[kTopWall].normal_force + pore) / width;
    }
    samples.push_back(sample);
  };
  record(sim);
  RunControl control;
  control.at_step_end = [&](const Simulation& now) {
    if (now.step() % every == 0 || now.finished()) record(now);
    if (isochrones != nullptr && now.step() % every == 0)
      isochrones->push_back(MeasureIsochrone(now));
  };
  const Status status = sim.Run(control);
  EXPECT_TRUE(status.ok()) << status.message();
  return samples;
}

// The walled column's own vertical permeability: steady flow from a drained base platen at dp to
// the top platen at 0 through the resting column (no load, no coupling), k = mu Q H / (W dp).
// The walls change the hydraulics next to them (the pores along the side walls are larger and
// their feet are pipes of length R), so k is measured with them. A thin fluid brings the column
// to steady flow in a few hundred steps; k does not depend on mu. `column`'s first effect is its
// contacts effect.
inline double WalledPermeability(const SceneSpec& column, double platen_conductance) {
  constexpr double kThin = 1e-2;  // viscosity factor
  constexpr double kDp = 1e3;     // Pa
  SceneSpec s = column;
  s.fluid.viscosity_pa_s = kThin * column.fluid.viscosity_pa_s;
  s.solver.end_time_s = 3e-3;
  s.stages.clear();
  WallsEffectSpec walls;
  walls.walls = {Drained(SideWall(WallSide::kBottom), kDp, platen_conductance),
                 SideWall(WallSide::kLeft), SideWall(WallSide::kRight),
                 Drained(SideWall(WallSide::kTop), 0.0, platen_conductance)};
  s.effects = {column.effects.front(), walls, FlowEffectSpec{}};
  Result<Simulation> created = Simulation::Create(s);
  EXPECT_TRUE(created.ok()) << created.status().message();
  if (!created.ok()) return 0.0;
  Simulation& sim = *created;
  EXPECT_TRUE(sim.Run({}).ok());
  const LiveState& state = sim.stepper().state();
  const FlowNetwork& flow = state.net.flow;
  const std::int32_t top = state.net.wall_node[kTopWall];
  double q = 0.0;
  for (std::size_t p = 0; p < flow.num_pipes(); ++p) {
    if (flow.pipe_domain_b()[p] != top) continue;
    const auto a = static_cast<std::size_t>(flow.pipe_domain_a()[p]);
    q += flow.pipe_conductance()[p] *
         (flow.pressure()[a] - flow.pressure()[static_cast<std::size_t>(top)]);
  }
  const double height = state.walls[kTopWall].py - state.walls[kBottomWall].py;
  const double width = state.walls[kRightWall].px - state.walls[kLeftWall].px;
  return s.fluid.viscosity_pa_s * q * height / (width * kDp);
}

// Mean of `field` over the samples with t in [from, to].
template <typename Field>
double WindowMean(const std::vector<Sample>& samples, double from, double to, Field field) {
  double sum = 0.0;
  int count = 0;
  for (const Sample& s : samples) {
    if (s.t >= from && s.t <= to) {
      sum += field(s);
      ++count;
    }
  }
  return count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
}

// Settlement at time t, linear between samples.
inline double SettlementAt(const std::vector<Sample>& samples, double t) {
  for (std::size_t k = 1; k < samples.size(); ++k) {
    if (samples[k].t >= t) {
      const Sample& a = samples[k - 1];
      const Sample& b = samples[k];
      return a.settlement + (b.settlement - a.settlement) * (t - a.t) / (b.t - a.t);
    }
  }
  return samples.back().settlement;
}

// When a load increment of `step` Pa, put on from `from` (the platen's total stress rising from
// `before` towards before + step over the samples from then on), acts as if applied at once: the
// load history's centroid from + integral of (1 - (sigma(t) - before) / step) dt. Integrated up to
// `to` (the next increment's start, or the run's end).
inline double LoadCentroid(const std::vector<Sample>& samples, double from, double to,
                           double before, double step) {
  double t0 = from;
  for (std::size_t j = 1; j < samples.size(); ++j) {
    if (samples[j - 1].t < from || samples[j].t > to) continue;
    const double mean = 0.5 * (samples[j].top_stress + samples[j - 1].top_stress);
    const double lag = 1.0 - (mean - before) / step;
    t0 += std::max(lag, 0.0) * (samples[j].t - samples[j - 1].t);
  }
  return t0;
}

// The DEM is bit-identical on any thread count (dem_parallel.h); on a shared two-core machine its
// OpenMP barriers spin for most of a step of a 400-disk column (30x slower measured), so the
// column tests run it on one thread.
class OneThread {
 public:
  OneThread() : before_(omp_get_max_threads()) { omp_set_num_threads(1); }
  ~OneThread() { omp_set_num_threads(before_); }

 private:
  int before_;
};

}  // namespace seep::core::terzaghi_probe
