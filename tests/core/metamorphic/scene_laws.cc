#include "scene_laws.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <stop_token>
#include <utility>
#include <vector>

#include "seep/core/run/simulation.h"
#include "seep/core/threads.h"

namespace seep::core::metamorphic {

// Where a run stands after its steps: its snapshot and report, and what the isometry law
// compares that the snapshot does not hold (domain centroids, wall stresses).
struct Outcome {
  std::string error;  // the run failed: why
  SimulationSnapshot snapshot;
  RunReport report;
  std::vector<double> centroid_x, centroid_y, domain_pressure;
  std::vector<double> wall_stress;
  double mean_radius = 0.0;
  double dt = 0.0;
  // Per step, the discrete events so far: contacts evaluated (disk pairs and disk-wall), bonds
  // broken and re-detections, the bonds open across a gap that carry a compressive force now, and
  // the loaded components local damping took as at rest.
  // Two runs whose counts part have met a discontinuity of the model on different sides: a
  // contact's onset, where its dashpot engages at once; a bond's strength; the aperture law's
  // branch, which the force's sign picks (aperture_law.h), so that a bond at rest across a gap
  // has a = a0 + m g at F = 0 and a0 at F = +1e-20 N/m, a rounding's force (seed 4306's mirror:
  // 0.085 Pa after two steps); local damping's rest threshold, where -alpha |f| sign(v) switches
  // on at once (seed 3514's translation).
  std::vector<std::array<std::uint64_t, 6>> events;
};

namespace {

// Bonded pairs apart (gap > 0) whose normal force is compressive: the aperture law takes its
// force branch for them, its gap branch at F <= 0.
std::uint64_t OpenBondsInCompression(const LiveState& live) {
  if (!live.contacts) return 0;
  std::vector<DemContactRecord> contacts;
  live.contacts->CollectContacts(&contacts);
  std::uint64_t count = 0;
  for (const DemContactRecord& c : contacts) {
    count += (c.bonded && c.gap > 0.0 && c.normal_force > 0.0) ? 1 : 0;
  }
  return count;
}

// Runs `scene` for `steps` steps (a steady scene: its one solve), stopped at `stop_at` (0: not)
// and resumed from that snapshot in a new simulation when asked.
Outcome RunScene(const SceneSpec& scene, std::uint64_t steps, std::uint64_t stop_at = 0) {
  Outcome out;
  Result<Simulation> created = Simulation::Create(scene);
  if (!created.ok()) {
    out.error = "create: " + created.status().message();
    return out;
  }
  Simulation sim = std::move(*created);
  const auto run_to = [&](Simulation& s, std::uint64_t last) -> Status {
    std::stop_source stop;
    RunControl control;
    control.stop = stop.get_token();
    control.at_step_end = [&](const Simulation& at) {
      const LiveState& live = at.stepper().state();
      const DemCounters& dem = live.counters.dem;
      out.events.push_back({dem.pair_evaluations, dem.wall_evaluations, dem.bonds_broken,
                            live.topology_version, OpenBondsInCompression(live),
                            dem.local_damping_at_rest});
      if (at.step() >= last) stop.request_stop();
    };
    const Status status = s.Run(control);
    return status.code() == StatusCode::kCancelled ? Status::Ok() : status;
  };
  if (stop_at > 0) {
    if (Status status = run_to(sim, stop_at); !status.ok()) {
      out.error = "run to the stop: " + status.message();
      return out;
    }
    const SimulationSnapshot mid = sim.TakeSnapshot();
    Result<Simulation> fresh = Simulation::Create(scene);
    if (!fresh.ok()) {
      out.error = "create after the stop: " + fresh.status().message();
      return out;
    }
    sim = std::move(*fresh);
    if (Status status = sim.Restore(mid); !status.ok()) {
      out.error = "restore: " + status.message();
      return out;
    }
  }
  if (Status status = run_to(sim, steps); !status.ok()) {
    out.error = fmt::format("run (step {}): {}", sim.step(), status.message());
    return out;
  }
  out.snapshot = sim.TakeSnapshot();
  out.report = sim.Report();
  const SceneNetwork& net = sim.network();
  const std::size_t domains = net.domains.num_domains();
  out.centroid_x = net.domains.centroid_x;
  out.centroid_y = net.domains.centroid_y;
  const auto pressure = net.flow.pressure();
  out.domain_pressure.assign(pressure.begin(), pressure.begin() + static_cast<long>(domains));
  out.wall_stress = sim.stepper().state().wall_stress_pa;
  const ParticleView p = sim.particles();
  for (std::size_t i = 0; i < p.size(); ++i) out.mean_radius += p.radius[i];
  out.mean_radius /= static_cast<double>(std::max<std::size_t>(1, p.size()));
  out.dt = sim.dt_s();
  return out;
}

bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

// The first field in which two snapshots differ, bit for bit ("" when none).
std::string SnapshotDifference(const SimulationSnapshot& a, const SimulationSnapshot& b) {
  if (a.step != b.step) return fmt::format("step {} against {}", a.step, b.step);
  if (!SameBits(a.time_s, b.time_s)) return fmt::format("time {} against {}", a.time_s, b.time_s);
  if (!SameBits(a.pressure, b.pressure)) return "pressures";
  if (!SameBits(a.series.values, b.series.values)) return "series";
  if (a.ledger.has_value() != b.ledger.has_value()) return "books kept in one only";
  if (a.ledger) {
    const FluidLedger& x = *a.ledger;
    const FluidLedger& y = *b.ledger;
    if (!SameBits(
            {x.injected_m2, x.compressed_m2, x.pore_growth_m2, x.redetection_m2, x.handled_m2},
            {y.injected_m2, y.compressed_m2, y.pore_growth_m2, y.redetection_m2, y.handled_m2}) ||
        !SameBits(x.left_m2, y.left_m2)) {
      return "books";
    }
  }
  if (a.mechanics.has_value() != b.mechanics.has_value()) return "mechanics in one only";
  if (a.mechanics) {
    const MechanicsSnapshot& x = *a.mechanics;
    const MechanicsSnapshot& y = *b.mechanics;
    const std::pair<const char*, std::pair<const std::vector<double>*, const std::vector<double>*>>
        fields[] = {{"x", {&x.x, &y.x}},
                    {"y", {&x.y, &y.y}},
                    {"vx", {&x.vx, &y.vx}},
                    {"vy", {&x.vy, &y.vy}},
                    {"omega", {&x.omega, &y.omega}},
                    {"fx", {&x.fx, &y.fx}},
                    {"fy", {&x.fy, &y.fy}},
                    {"torque", {&x.torque, &y.torque}},
                    {"walls", {&x.walls, &y.walls}},
                    {"apparent_volume", {&x.apparent_volume, &y.apparent_volume}},
                    {"pore_volume", {&x.pore_volume, &y.pore_volume}},
                    {"aperture", {&x.aperture, &y.aperture}}};
    for (const auto& [name, pair] : fields) {
      if (!SameBits(*pair.first, *pair.second)) return fmt::format("mechanics.{}", name);
    }
    if (x.topology_version != y.topology_version) return "topology version";
    if (!SameBits(x.dt, y.dt) || x.flow_every != y.flow_every) return "clock";
    const EffectStates& e = x.effects;
    const EffectStates& f = y.effects;
    if (e.contacts.bonds_broken != f.contacts.bonds_broken ||
        e.redetection.redetections != f.redetection.redetections ||
        !SameBits(e.redetection.breakthrough_time_s, f.redetection.breakthrough_time_s) ||
        !SameBits(e.injection.peak_well_pressure_pa, f.injection.peak_well_pressure_pa) ||
        e.flow.max_sub_steps != f.flow.max_sub_steps) {
      return "effect states";
    }
  }
  return "";
}

std::string MetricsDifference(const RunReport& a, const RunReport& b) {
  if (a.metrics.size() != b.metrics.size()) {
    return fmt::format("{} metrics against {}", a.metrics.size(), b.metrics.size());
  }
  for (std::size_t k = 0; k < a.metrics.size(); ++k) {
    if (a.metrics[k].first != b.metrics[k].first) {
      return fmt::format("metric {} against {}", a.metrics[k].first, b.metrics[k].first);
    }
    if (!SameBits(a.metrics[k].second, b.metrics[k].second)) {
      return fmt::format("metric {}: {:.17g} against {:.17g}", a.metrics[k].first,
                         a.metrics[k].second, b.metrics[k].second);
    }
  }
  return "";
}

// The largest |a - b| / scale over matched values, and where.
struct Deviation {
  double worst = 0.0;
  std::string where;
  void Fail(const std::string& what) {
    worst = std::numeric_limits<double>::infinity();
    where = what + ":";
  }
  // `name` makes the quantity's name, only for a new worst (most values are not).
  template <typename Name>
  void Add(double a, double b, double scale, Name name) {
    const double d = std::abs(a - b) / scale;
    if (!(d <= worst)) {  // NaN counts as the worst
      worst = d;
      where =
          fmt::format("{}: {:.17g} against its image {:.17g} (scale {:.3g})", name(), a, b, scale);
    }
  }
};

// How far b is from the image of a under `map`, each quantity against its scale (scene_laws.h).
Deviation Compare(const Outcome& a, const Outcome& b, const SceneMap& map, double bulk_modulus) {
  Deviation dev;
  if (a.snapshot.step != b.snapshot.step) {
    dev.Fail(fmt::format("{} steps against {}", a.snapshot.step, b.snapshot.step));
    return dev;
  }
  if (a.snapshot.mechanics && b.snapshot.mechanics) {
    const MechanicsSnapshot& x = *a.snapshot.mechanics;
    const MechanicsSnapshot& y = *b.snapshot.mechanics;
    const double length = a.mean_radius;
    double speed = 0.0;
    for (std::size_t i = 0; i < x.vx.size(); ++i) {
      speed = std::max(speed, std::hypot(x.vx[i], x.vy[i]));
    }
    const double step_length = length + speed * a.dt;
    for (std::size_t i = 0; i < x.x.size() && i < y.x.size(); ++i) {
      double px, py, vx, vy;
      map.Point(x.x[i], x.y[i], &px, &py);
      map.Vector(x.vx[i], x.vy[i], &vx, &vy);
      dev.Add(px, y.x[i], length, [&] { return fmt::format("particle {} x", i); });
      dev.Add(py, y.y[i], length, [&] { return fmt::format("particle {} y", i); });
      dev.Add(vx * a.dt, y.vx[i] * a.dt, step_length,
              [&] { return fmt::format("particle {} vx dt", i); });
      dev.Add(vy * a.dt, y.vy[i] * a.dt, step_length,
              [&] { return fmt::format("particle {} vy dt", i); });
    }
    // Walls: the line's offset n.p (any point of the line gives it) and its normal speed.
    for (std::size_t w = 0; 6 * w + 5 < x.walls.size() && 6 * w + 5 < y.walls.size(); ++w) {
      const double* u = &x.walls[6 * w];
      const double* v = &y.walls[6 * w];
      double nx, ny;
      map.Vector(u[2], u[3], &nx, &ny);
      const double offset = u[0] * u[2] + u[1] * u[3] + nx * map.tx + ny * map.ty;
      dev.Add(offset, v[0] * v[2] + v[1] * v[3], length,
              [&] { return fmt::format("wall {} line", w); });
      dev.Add((u[4] * u[2] + u[5] * u[3]) * a.dt, (v[4] * v[2] + v[5] * v[3]) * a.dt, step_length,
              [&] { return fmt::format("wall {} normal speed dt", w); });
    }
  }
  // Pressures of the domains, matched by centroid (a turned network numbers them otherwise).
  if (a.domain_pressure.size() != b.domain_pressure.size()) {
    dev.Fail(
        fmt::format("{} domains against {}", a.domain_pressure.size(), b.domain_pressure.size()));
    return dev;
  }
  // A pressure is K_f times the fluid's volumetric strain: its scale is the fluid's stiffness
  // (or the largest pressure, if larger), so the law holds the fluid content of each domain to
  // kIsometryTolerance. Against the largest pressure alone a stiff fluid would turn the rounding
  // of the geometry (1e-16 of a coordinate) into K_f / P times as much pressure.
  double pressure_scale = bulk_modulus;
  for (const double p : a.snapshot.pressure) pressure_scale = std::max(pressure_scale, std::abs(p));
  std::map<std::pair<long long, long long>, std::size_t> by_cell;
  const double cell = 1e-6 * a.mean_radius;
  const auto key = [&](double x, double y) {
    return std::pair{std::llround(x / cell), std::llround(y / cell)};
  };
  for (std::size_t d = 0; d < b.centroid_x.size(); ++d) {
    by_cell[key(b.centroid_x[d], b.centroid_y[d])] = d;
  }
  for (std::size_t d = 0; d < a.centroid_x.size(); ++d) {
    double cx, cy;
    map.Point(a.centroid_x[d], a.centroid_y[d], &cx, &cy);
    std::optional<std::size_t> match;
    const auto [kx, ky] = key(cx, cy);
    for (long long i = -1; i <= 1 && !match; ++i) {
      for (long long j = -1; j <= 1 && !match; ++j) {
        if (const auto it = by_cell.find({kx + i, ky + j}); it != by_cell.end()) match = it->second;
      }
    }
    if (!match) {
      dev.Fail(fmt::format("domain {} (centroid {}, {}) has no image", d, a.centroid_x[d],
                           a.centroid_y[d]));
      return dev;
    }
    dev.Add(a.domain_pressure[d], b.domain_pressure[*match], pressure_scale,
            [&] { return fmt::format("domain {} pressure", d); });
  }
  // The walls feel the pore pressure: the same scale (or the largest stress, if larger).
  double stress_scale = pressure_scale;
  for (const double s : a.wall_stress) stress_scale = std::max(stress_scale, std::abs(s));
  for (std::size_t w = 0; w < a.wall_stress.size() && w < b.wall_stress.size(); ++w) {
    dev.Add(a.wall_stress[w], b.wall_stress[w], stress_scale,
            [&] { return fmt::format("wall {} stress", w); });
  }
  return dev;
}

// A run of the scene and its outcome's failure, if any, as the law reports it.
std::optional<std::string> BothRanOrBothFailed(const Outcome& a, const Outcome& b,
                                               const std::string& what) {
  if (a.error.empty() == b.error.empty()) return std::nullopt;
  return fmt::format("{}: the original {}, the other {}", what,
                     a.error.empty() ? "ran" : "failed (" + a.error + ")",
                     b.error.empty() ? "ran" : "failed (" + b.error + ")");
}

}  // namespace

SceneMap SeedTranslation(std::uint64_t seed) {
  return {Turn::kNone, (static_cast<double>(seed % 7) - 3.0) * 0.0625 + 0.03125,
          (static_cast<double>(seed % 5) - 2.0) * 0.046875};
}

std::uint64_t SeedResumeStep(std::uint64_t seed, std::uint64_t steps) {
  return 1 + seed % (steps - 1);
}

LawScene::LawScene(const SceneSpec& generated)
    : generated_(generated), materialised_(MaterialisedScene(generated)) {}

LawScene::~LawScene() = default;

const Outcome& LawScene::Run(std::uint64_t steps) const {
  std::unique_ptr<Outcome>& run = runs_[steps];
  if (!run) run = std::make_unique<Outcome>(RunScene(materialised_, steps));
  return *run;
}

double RoundingSpread(const LawScene& scene, std::uint64_t steps, double frame) {
  const SceneSpec& base = scene.materialised();
  const Outcome& a = scene.Run(steps);
  if (!a.error.empty()) return 0.0;
  double spread = 0.0;
  // Two patterns of every coordinate and radius one ulp up or down (a map rounds every position
  // update otherwise, and decides ties as a wall placed against the outermost disk, at y + r,
  // otherwise), then K_f one ulp higher (the fluid's stiffness amplifies rounding).
  for (int nudge = 0; nudge < 3; ++nudge) {
    SceneSpec nudged = base;
    if (nudge < 2) {
      auto& list = std::get<ParticleListSpec>(nudged.packing.source);
      std::uint64_t bits = 0x9E3779B97F4A7C15ull * static_cast<std::uint64_t>(nudge + 1);
      for (std::vector<double>* v : {&list.x_m, &list.y_m, &list.radius_m}) {
        for (double& c : *v) {
          bits ^= bits << 13;
          bits ^= bits >> 7;
          bits ^= bits << 17;
          // One ulp of |c| + frame: a multiple of c's own, so c +- it is exact.
          const double magnitude = std::abs(c) + frame;
          const double ulp = std::nextafter(magnitude, 2.0 * magnitude + 1.0) - magnitude;
          c += (bits & 1) != 0 ? ulp : -ulp;
        }
      }
    } else {
      nudged.fluid.bulk_modulus_pa =
          std::nextafter(nudged.fluid.bulk_modulus_pa, 2.0 * nudged.fluid.bulk_modulus_pa);
    }
    const Outcome b = RunScene(nudged, steps);
    if (!b.error.empty()) return std::numeric_limits<double>::infinity();
    spread = std::max(spread, Compare(a, b, SceneMap{}, base.fluid.bulk_modulus_pa).worst);
  }
  return spread;
}

std::string CheckIsometry(const LawScene& scene, std::uint64_t steps, const SceneMap& map,
                          double spread) {
  const MappedScene image = MapScene(scene.generated(), map);
  if (!image.scene) return "";  // not expressible as a scene: nothing to check
  const Outcome& full = scene.Run(steps);
  Outcome b = RunScene(*image.scene, steps);
  if (auto failed = BothRanOrBothFailed(full, b, map.Name())) return *failed;
  if (!full.error.empty()) return "";  // both failed alike: the stability guards say why
  // Where the two runs met a discontinuity on different sides (events.size() is the steps run),
  // they are compared at the step before: up to there they must be each other's image.
  std::uint64_t parted = 0;
  while (parted < full.events.size() && parted < b.events.size() &&
         full.events[parted] == b.events[parted]) {
    ++parted;
  }
  const bool part = parted < full.events.size() || parted < b.events.size();
  std::string where_compared;
  if (part) {
    if (parted == 0) return "";  // parted at the first step: nothing before to compare
    b = RunScene(*image.scene, parted);
    where_compared =
        fmt::format(" (compared before step {}, where a discrete event differed)", parted + 1);
  }
  const Outcome& a = part ? scene.Run(parted) : full;
  const Deviation dev = Compare(a, b, map, scene.materialised().fluid.bulk_modulus_pa);
  double tolerance = std::max(kIsometryTolerance, kSpreadFactor * spread);
  if (dev.worst <= tolerance) return "";
  const double frame = std::max(std::abs(map.tx), std::abs(map.ty));
  if (frame > 0.0 && a.snapshot.step > 1) {
    const std::uint64_t compared = a.snapshot.step;
    spread =
        std::max(spread, RoundingSpread(scene, compared, frame) * static_cast<double>(compared));
    tolerance = std::max(kIsometryTolerance, kSpreadFactor * spread);
    if (dev.worst <= tolerance) return "";
  }
  return fmt::format(
      "{}: after {} steps{} {} deviates by {:.3g} of its scale (tolerance {:.3g}: {:.0e}, or {} "
      "x the {:.3g} one rounding makes): {}",
      map.Name(), a.snapshot.step, where_compared, dev.where.substr(0, dev.where.find(':')),
      dev.worst, tolerance, kIsometryTolerance, kSpreadFactor, spread, dev.where);
}

std::string CheckResume(const LawScene& scene, std::uint64_t steps, std::uint64_t stop_at) {
  const Outcome& whole = scene.Run(steps);
  const Outcome resumed = RunScene(scene.materialised(), steps, stop_at);
  if (whole.error != resumed.error) {
    return fmt::format("resumed at step {}: the uninterrupted run {}, the resumed one {}", stop_at,
                       whole.error.empty() ? "ran" : whole.error,
                       resumed.error.empty() ? "ran" : resumed.error);
  }
  if (!whole.error.empty()) return "";
  if (std::string d = SnapshotDifference(whole.snapshot, resumed.snapshot); !d.empty()) {
    return fmt::format("resumed at step {}: state differs ({})", stop_at, d);
  }
  if (std::string d = MetricsDifference(whole.report, resumed.report); !d.empty()) {
    return fmt::format("resumed at step {}: {}", stop_at, d);
  }
  return "";
}

std::string CheckThreads(const LawScene& scene, std::uint64_t steps) {
  // Every loop goes to the team, however small the scene (threads.h).
  SetMinParallelItemsForThisThread(1);
  SetCoreThreadsForThisThread(1);
  const Outcome one = RunScene(scene.materialised(), steps);
  SetCoreThreadsForThisThread(2);
  const Outcome two = RunScene(scene.materialised(), steps);
  SetCoreThreadsForThisThread(1);
  SetMinParallelItemsForThisThread(0);
  if (one.error != two.error) {
    return fmt::format("1 thread {}, 2 threads {}", one.error.empty() ? "ran" : one.error,
                       two.error.empty() ? "ran" : two.error);
  }
  if (!one.error.empty()) return "";
  if (std::string d = SnapshotDifference(one.snapshot, two.snapshot); !d.empty()) {
    return "2 threads against 1: state differs (" + d + ")";
  }
  if (std::string d = MetricsDifference(one.report, two.report); !d.empty()) {
    return "2 threads against 1: " + d;
  }
  return "";
}

std::string CheckBooks(const LawScene& scene, std::uint64_t steps) {
  const Outcome& run = scene.Run(steps);
  if (!run.error.empty() || !run.snapshot.ledger) return "";
  const FluidLedger& books = *run.snapshot.ledger;
  if (books.handled_m2 > 0.0) {
    if (books.relative_error() <= kBooksTolerance) return "";
    const double left = std::accumulate(books.left_m2.begin(), books.left_m2.end(), 0.0);
    return fmt::format(
        "books: injected {:.6g} - left {:.6g} + redetection {:.6g} - stored {:.6g} = {:.3g} m^2, "
        "{:.3g} of the {:.6g} m^2 handled (tolerance {:.0e})",
        books.injected_m2, left, books.redetection_m2, books.stored_m2(), books.imbalance_m2(),
        books.relative_error(), books.handled_m2, kBooksTolerance);
  }
  // Nothing handled: whatever the pores gave up must be what the fluid was compressed by.
  const double scale = std::max(std::abs(books.compressed_m2), std::abs(books.pore_growth_m2));
  if (std::abs(books.compressed_m2 + books.pore_growth_m2) <= kBooksTolerance * scale) return "";
  return fmt::format(
      "books: nothing handled, yet compressed {:.17g} + pore growth {:.17g} = {:.3g} m^2",
      books.compressed_m2, books.pore_growth_m2, books.compressed_m2 + books.pore_growth_m2);
}

}  // namespace seep::core::metamorphic
