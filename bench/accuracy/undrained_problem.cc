// The undrained-loading problem of the coupled grid (see undrained_problem.h).
#include "undrained_problem.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <utility>

#include "seep/core/flow/flow_diagnostics.h"

namespace seep::bench {
namespace {

using core::SceneSpec;

constexpr double kLoad = 3.5e4;         // Pa on every wall
constexpr double kServoMaxSpeed = 0.2;  // m/s
// Thin enough that the pressure evens out inside the sample within ~1 ms; u does not depend on it.
constexpr double kViscosity = 7.5e-7;  // Pa s
constexpr double kEndTime = 0.008;     // s; the load is on within ~2 ms
constexpr double kWindowStart = 0.004;

struct Size {
  std::uint32_t columns, rows;
};
constexpr Size kSizes[] = {{14, 12}, {24, 20}, {34, 28}};

core::WallsEffectSpec Walls() {
  core::WallsEffectSpec walls;
  for (const core::WallSide side : {core::WallSide::kBottom, core::WallSide::kLeft,
                                    core::WallSide::kRight, core::WallSide::kTop}) {
    walls.walls.push_back(core::SideWall(side, kLoad, 0.5, kServoMaxSpeed));
  }
  return walls;
}

SceneSpec SealedSample(const Size& size) {
  return WalledLattice(fmt::format("undrained-{}x{}", size.columns, size.rows), size.columns,
                       size.rows, kViscosity, Walls(), kEndTime);
}

double BoxArea(const core::LiveState& state) {
  return (state.walls[2].px - state.walls[1].px) * (state.walls[3].py - state.walls[0].py);
}

// The drained skeleton's bulk modulus: the load on the sample without fluid, to rest.
double DrainedBulkModulus(const Size& size) {
  SceneSpec s = SealedSample(size);
  s.solver.end_time_s = 0.03;
  s.effects = {SoftLatticeContacts(0.2), Walls(), core::LocalDampingEffectSpec{0.7}};
  core::Result<core::Simulation> sim = core::Simulation::Create(s);
  if (!sim.ok()) return std::numeric_limits<double>::quiet_NaN();
  const double area0 = BoxArea(sim->stepper().state());
  if (!sim->Run({}).ok()) return std::numeric_limits<double>::quiet_NaN();
  return kLoad / (1.0 - BoxArea(sim->stepper().state()) / area0);
}

}  // namespace

CoupledGrid DefaultUndrainedGrid(bool full) {
  CoupledGrid g;
  g.bulk_moduli = {2.2e9, 2.2e8, 2.2e7, 4e6, 1e6};
  g.flow_every = {4, 16};
  g.dt_safety = {0.5, 0.25, 0.8};
  g.sizes = full ? 3 : 2;
  return g;
}

void RunUndrainedGrid(const CoupledGrid& grid, std::vector<AccuracyRun>& rows) {
  std::vector<double> bulk(static_cast<std::size_t>(grid.sizes));
  for (std::size_t i = 0; i < bulk.size(); ++i) bulk[i] = DrainedBulkModulus(kSizes[i]);
  const std::size_t first = rows.size();
  const std::vector<CoupledChoice> choices = CoupledChoices(grid);
  std::vector<double> shares;
  for (const CoupledChoice& choice : choices) {
    const Size& size = kSizes[choice.size];
    SceneSpec scene = SealedSample(size);
    ApplyChoice(choice, &scene);
    double sum = 0.0;
    int count = 0;
    const CoupledRun run = RunCoupled(scene, [&](const core::Simulation& now) {
      if (now.time_s() < kWindowStart) return false;
      sum += core::VolumeWeightedMeanPressure(now.stepper().state().net.flow,
                                              core::StorageVolume::kApparent);
      ++count;
      return false;
    });
    const double k = bulk[static_cast<std::size_t>(choice.size)];
    const double real = (kRealWaterBulkModulusPa / kLatticeStoragePorosity) /
                        (kRealWaterBulkModulusPa / kLatticeStoragePorosity + k);
    const double own = (choice.bulk_modulus_pa / kLatticeStoragePorosity) /
                       (choice.bulk_modulus_pa / kLatticeStoragePorosity + k);
    const double measured = count > 0 ? sum / count / kLoad : std::nan("");
    const double error = std::abs(measured - real) / real;
    shares.push_back(measured);
    const int particles = static_cast<int>(size.columns * size.rows);
    rows.push_back(CoupledRow(
        "undrained", choice, particles, run, error, "|du/dsigma - real water|/real water",
        fmt::format("du/dsigma {:.4f} (own K_f {:.4f}; real water {:.4f}); K {:.4g} Pa", measured,
                    own, real, k)));
    PrintCoupledProgress(rows.back(), choice, particles, "");
  }
  // Against the same sample's run at real water (the base choice at that size).
  const std::vector<std::size_t> base = RealWaterBaseIndices(choices, grid);
  for (std::size_t i = 0; i < choices.size(); ++i) {
    rows[first + i].real_water_error = std::abs(shares[i] - shares[base[i]]) / shares[base[i]];
  }
}

}  // namespace seep::bench
