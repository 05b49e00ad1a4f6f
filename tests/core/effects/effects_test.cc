// The effect registry and the coupled step loop: "only the effects a scene calls for", canonical
// hook order, validation of effect lists, bit-identical resume of a moving scene and bit-identical
// runs on 1 and 2 threads, the pore volumes a snapshot carries, the per-effect timing.
#include <gtest/gtest.h>
#include <omp.h>

#include <chrono>
#include <cstring>

#include "coupled_scenes.h"
#include "seep/core/coupling/domain_volume_update.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"

namespace seep::core {
namespace {

using effects_test::BoxedLatticeScene;
using effects_test::Contacts;
using effects_test::MustCreate;
using effects_test::MustRun;
using effects_test::ResumedAt;
using effects_test::WithOpenEnds;

// Contacts and flow only: every counter of an unlisted effect stays zero, the listed ones work.
TEST(Effects, UnlistedEffectsDoNoWork) {
  SceneSpec scene = WithOpenEnds(BoxedLatticeScene(8, 8));
  scene.effects = {Contacts(), FlowEffectSpec{}};
  Simulation sim = MustCreate(scene);
  MustRun(sim);
  const EffectCounters& c = sim.stepper().state().counters;
  EXPECT_GT(c.dem.integrations, 0u);
  EXPECT_GT(c.dem.pair_evaluations, 0u);
  EXPECT_GT(c.flow_updates, 0u);
  EXPECT_EQ(c.dem.gravity_applications, 0u);
  EXPECT_EQ(c.dem.local_damping_applications, 0u);
  EXPECT_EQ(c.dem.servo_updates, 0u);
  EXPECT_EQ(c.dem.wall_checks, 0u);
  EXPECT_EQ(c.dem.wall_evaluations, 0u);
  EXPECT_EQ(c.dem.bond_evaluations, 0u);
  EXPECT_EQ(c.pressure_force_passes, 0u);
  EXPECT_EQ(c.volume_updates, 0u);
  EXPECT_EQ(c.aperture_updates, 0u);
  EXPECT_EQ(c.topology_checks, 0u);
  EXPECT_EQ(c.redetections, 0u);
  EXPECT_EQ(c.injection_updates, 0u);
}

// The same box with everything listed: each effect's counter moves.
TEST(Effects, ListedEffectsEachDoTheirWork) {
  SceneSpec scene = BoxedLatticeScene(8, 8);
  BondsEffectSpec bonds;
  bonds.params = {1e9, 5e8, 1.0, 1e7, 1e7};
  bonds.tolerance_m = 1e-6;
  scene.effects.push_back(bonds);
  scene.effects.push_back(RedetectionEffectSpec{});
  Simulation sim = MustCreate(scene);
  MustRun(sim);
  const EffectCounters& c = sim.stepper().state().counters;
  EXPECT_GT(c.dem.gravity_applications, 0u);
  EXPECT_GT(c.dem.local_damping_applications, 0u);
  EXPECT_GT(c.dem.servo_updates, 0u);
  EXPECT_GT(c.dem.wall_evaluations, 0u);
  EXPECT_GT(c.dem.bond_evaluations, 0u);
  EXPECT_GT(c.pressure_force_passes, 0u);
  EXPECT_GT(c.volume_updates, 0u);
  EXPECT_GT(c.aperture_updates, 0u);
  EXPECT_GT(c.topology_checks, 0u);
  EXPECT_EQ(c.volume_updates, c.flow_updates);
  EXPECT_EQ(c.aperture_updates, c.flow_updates);
}

// A flow-only scene (no effects listed) builds no step loop and detects nothing after set-up.
TEST(Effects, FlowOnlySceneDetectsNothingAfterSetUp) {
  SceneSpec scene = WithOpenEnds(BoxedLatticeScene(12, 10));
  scene.effects.clear();
  const std::uint64_t contacts_before = ContactDetectionCalls();
  const std::uint64_t domains_before = DomainDetectionCalls();
  Simulation sim = MustCreate(scene);
  EXPECT_FALSE(sim.stepper().state().moves());
  EXPECT_EQ(ContactDetectionCalls() - contacts_before, 1u);  // the set-up
  EXPECT_EQ(DomainDetectionCalls() - domains_before, 1u);
  MustRun(sim);
  EXPECT_GT(sim.step(), 100u);
  EXPECT_EQ(ContactDetectionCalls() - contacts_before, 1u);
  EXPECT_EQ(DomainDetectionCalls() - domains_before, 1u);
}

// The hook lists run in the canonical order whatever order the scene lists the effects in.
TEST(Effects, HookListsFollowTheCanonicalOrder) {
  SceneSpec scene = WithOpenEnds(BoxedLatticeScene(8, 8));
  scene.effects = {ApertureUpdateEffectSpec{},
                   FluidForcesEffectSpec{},
                   FlowEffectSpec{},
                   LocalDampingEffectSpec{0.3},
                   GravityEffectSpec{},
                   VolumeChangeEffectSpec{},
                   Contacts(),
                   RedetectionEffectSpec{}};
  Simulation sim = MustCreate(scene);
  using Names = std::vector<std::string_view>;
  EXPECT_EQ(sim.stepper().HookList(kForceHook), (Names{"contacts", "gravity", "fluid_forces"}));
  EXPECT_EQ(sim.stepper().HookList(kPostForceHook), (Names{"local_damping"}));
  EXPECT_EQ(sim.stepper().HookList(kFlowUpdateHook), (Names{"volume_change", "flow"}));
  EXPECT_EQ(sim.stepper().HookList(kEndOfStepHook), (Names{"aperture_update", "redetection"}));
}

TEST(Effects, BadListsNameTheEntryAndTheReason) {
  SceneSpec scene = WithOpenEnds(BoxedLatticeScene(6, 6));
  scene.effects = {FlowEffectSpec{}, GravityEffectSpec{}};
  Status status = ValidateScene(scene);
  EXPECT_EQ(status.message(),
            "scene.effects[1].gravity: requires the contacts effect (without it the particles do "
            "not move); on a frozen packing gravity can weigh the fluid: set fluid.density_kg_m3 "
            "> 0");
  scene.fluid.density_kg_m3 = 1000.0;  // then it weighs the fluid of the frozen packing
  EXPECT_TRUE(ValidateScene(scene).ok()) << ValidateScene(scene).message();
  scene.fluid.density_kg_m3 = 0.0;
  scene.effects = {Contacts(), GravityEffectSpec{}, GravityEffectSpec{}};
  EXPECT_EQ(ValidateScene(scene).message(),
            "scene.effects[2].gravity: listed twice (each effect at most once)");
  scene.effects = {Contacts(), FluidForcesEffectSpec{}};
  EXPECT_EQ(ValidateScene(scene).message(),
            "scene.effects[1].fluid_forces: requires the flow effect (there is no fluid to "
            "couple)");
  scene.effects = {Contacts(), FlowEffectSpec{}, InjectionEffectSpec{1e-6}};
  EXPECT_EQ(ValidateScene(scene).message(),
            "scene.effects[2].injection: injects into the well of a radial boundary; set "
            "scene.boundary.radial");
  ContactsEffectSpec bad = Contacts();
  bad.dt_safety = 1.5;
  scene.effects = {bad};
  EXPECT_EQ(ValidateScene(scene).message(),
            "scene.effects[0].contacts.dt_safety: must lie in (0, 1] (got 1.5)");
  scene.effects = {Contacts(), FlowEffectSpec{}};
  scene.solver.kind = SolverKind::kSteady;
  EXPECT_EQ(
      ValidateScene(scene).message().rfind("scene.solver.kind: a scene whose particles move", 0),
      0u);
}

template <typename T>
bool BitEqual(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// The state of two runs of a moving scene, bit for bit (particles, walls, contacts, pressures,
// volumes, apertures).
void ExpectSameState(const SimulationSnapshot& got, const SimulationSnapshot& expected) {
  ASSERT_TRUE(got.mechanics && expected.mechanics);
  EXPECT_EQ(got.step, expected.step);
  EXPECT_TRUE(BitEqual(got.pressure, expected.pressure));
  EXPECT_TRUE(BitEqual(got.mechanics->x, expected.mechanics->x));
  EXPECT_TRUE(BitEqual(got.mechanics->y, expected.mechanics->y));
  EXPECT_TRUE(BitEqual(got.mechanics->vx, expected.mechanics->vx));
  EXPECT_TRUE(BitEqual(got.mechanics->omega, expected.mechanics->omega));
  EXPECT_TRUE(BitEqual(got.mechanics->fx, expected.mechanics->fx));
  EXPECT_TRUE(BitEqual(got.mechanics->torque, expected.mechanics->torque));
  EXPECT_TRUE(BitEqual(got.mechanics->walls, expected.mechanics->walls));
  EXPECT_TRUE(
      BitEqual(got.mechanics->contacts.pair_shear, expected.mechanics->contacts.pair_shear));
  EXPECT_TRUE(BitEqual(got.mechanics->apparent_volume, expected.mechanics->apparent_volume));
  EXPECT_TRUE(BitEqual(got.mechanics->pore_volume, expected.mechanics->pore_volume));
  EXPECT_TRUE(BitEqual(got.mechanics->aperture, expected.mechanics->aperture));
  EXPECT_EQ(got.mechanics->effects.contacts.bonds_broken,
            expected.mechanics->effects.contacts.bonds_broken);
  ASSERT_TRUE(got.ledger && expected.ledger);
  EXPECT_TRUE(BitEqual(got.ledger->left_m2, expected.ledger->left_m2));
  EXPECT_TRUE(
      BitEqual(std::vector<double>{got.ledger->injected_m2, got.ledger->compressed_m2,
                                   got.ledger->pore_growth_m2, got.ledger->redetection_m2,
                                   got.ledger->handled_m2},
               std::vector<double>{expected.ledger->injected_m2, expected.ledger->compressed_m2,
                                   expected.ledger->pore_growth_m2, expected.ledger->redetection_m2,
                                   expected.ledger->handled_m2}));
}

// Stop part-way, snapshot, restore into a fresh simulation, finish: the state equals that of an
// uninterrupted run bit for bit (particles, walls, contacts, pressures, series).
TEST(Effects, ResumeOfAMovingSceneIsBitIdentical) {
  SceneSpec scene = BoxedLatticeScene(10, 8);
  BondsEffectSpec bonds;
  bonds.params = {1e9, 5e8, 1.0, 1e3, 2e3};  // weak: some break under the load
  bonds.tolerance_m = 1e-6;
  scene.effects.push_back(bonds);
  scene.effects.push_back(RedetectionEffectSpec{});

  Simulation reference = MustCreate(scene);
  MustRun(reference);
  const SimulationSnapshot expected = reference.TakeSnapshot();

  // Stop a few steps after the first bond broke, so that the rest of the run breaks more bonds
  // and re-detects from the restored state.
  std::uint64_t stop_at = 0;
  SimulationSnapshot mid;
  Simulation resumed = ResumedAt(
      scene,
      [&](const Simulation& s) {
        if (stop_at == 0 && s.stepper().state().counters.dem.bonds_broken > 0) {
          stop_at = s.step() + 3;
        }
        return s.step() == stop_at;
      },
      &mid);
  ASSERT_FALSE(HasFailure());
  MustRun(resumed);
  const SimulationSnapshot got = resumed.TakeSnapshot();

  ASSERT_TRUE(got.mechanics && expected.mechanics);
  // The stretch after the resume must exercise what the snapshot has to carry.
  EXPECT_GT(expected.mechanics->effects.contacts.bonds_broken,
            mid.mechanics->effects.contacts.bonds_broken);
  EXPECT_GT(expected.mechanics->topology_version, 0u);
  ExpectSameState(got, expected);
  EXPECT_TRUE(BitEqual(got.series.values, expected.series.values));
  EXPECT_EQ(got.mechanics->topology_version, expected.mechanics->topology_version);
}

// Runs `steps` steps of `scene` on `threads` threads (and restores the thread count).
SimulationSnapshot RunOn(const SceneSpec& scene, int threads, std::uint64_t steps) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  Simulation sim = MustCreate(scene);
  std::stop_source stop;
  RunControl control;
  control.stop = stop.get_token();
  control.at_step_end = [&](const Simulation& s) {
    if (s.step() >= steps) stop.request_stop();
  };
  EXPECT_EQ(sim.Run(control).code(), StatusCode::kCancelled);
  SimulationSnapshot snap = sim.TakeSnapshot();
  omp_set_num_threads(before);
  return snap;
}

// Determinism across thread counts: a coupled lattice large enough that every parallel loop of
// the DEM and of the fluid effects (edges, domains, pipes, contacts: over 8192 items each) takes
// its parallel path ends bit-identical on 1 and 2 threads, bonds breaking on the way.
TEST(Effects, CoupledRunIsBitIdenticalOnOneAndTwoThreads) {
  SceneSpec scene = BoxedLatticeScene(100, 90);
  BondsEffectSpec bonds;
  bonds.params = {1e9, 5e8, 1.0, 3.0, 6.0};  // so weak that bonds break within the 40 steps
  bonds.tolerance_m = 1e-6;
  scene.effects.push_back(bonds);
  scene.effects.push_back(RedetectionEffectSpec{});
  const SimulationSnapshot one = RunOn(scene, 1, 40);
  const SimulationSnapshot two = RunOn(scene, 2, 40);
  ASSERT_TRUE(one.mechanics && two.mechanics);
  EXPECT_GT(one.pressure.size(), 8192u);
  EXPECT_EQ(one.step, 40u);
  ExpectSameState(two, one);
  EXPECT_GT(one.mechanics->effects.contacts.bonds_broken, 0u);
}

// With apparent storage the step keeps V_p at its detected value (it enters no equation), and
// every snapshot carries V_p fresh from the current positions: the updater's Compute on the
// network as detected, to the bit.
TEST(Effects, SnapshotCarriesCurrentPoreVolumesWithApparentStorage) {
  SceneSpec scene = BoxedLatticeScene(10, 8);
  scene.solver.storage = StorageVolume::kApparent;
  Simulation sim = MustCreate(scene);
  MustRun(sim);
  const SimulationSnapshot snap = sim.TakeSnapshot();
  ASSERT_TRUE(snap.mechanics);
  const DomainNetwork& detected = sim.network().domains;
  const std::size_t n = detected.num_domains();
  DomainVolumeUpdater updater;
  // The loops name the particles and then the wall vertices (radius 0): at detection where the
  // detection put them, now on the snapshot's walls.
  const std::size_t vertices = detected.walls.num_vertices();
  std::vector<double> radius = sim.network().packing.radius;
  radius.resize(radius.size() + vertices, 0.0);
  std::vector<double> x0 = snap.mechanics->detection_x, y0 = snap.mechanics->detection_y;
  x0.insert(x0.end(), detected.walls.vertex_x.begin(), detected.walls.vertex_x.end());
  y0.insert(y0.end(), detected.walls.vertex_y.begin(), detected.walls.vertex_y.end());
  std::vector<WallLine> lines;
  for (std::size_t w = 0; 6 * w < snap.mechanics->walls.size(); ++w) {
    const double* v = &snap.mechanics->walls[6 * w];
    lines.push_back({v[0], v[1], v[2], v[3]});
  }
  std::vector<double> x1 = snap.mechanics->x, y1 = snap.mechanics->y;
  x1.resize(x1.size() + vertices);
  y1.resize(y1.size() + vertices);
  const std::size_t particles = snap.mechanics->x.size();
  WallVertexPositions(detected.walls, snap.mechanics->x, snap.mechanics->y, lines,
                      std::span<double>(x1).subspan(particles),
                      std::span<double>(y1).subspan(particles));
  ASSERT_GT(vertices, 0u);
  ASSERT_TRUE(updater.Bind(ParticleView{x0, y0, radius}, detected).ok());
  std::vector<double> apparent(n), pore(n);
  ASSERT_TRUE(updater.Compute(ParticleView{x1, y1, radius}, detected, apparent, pore).ok());
  ASSERT_GE(snap.mechanics->pore_volume.size(), n);
  std::size_t moved = 0;
  for (std::size_t d = 0; d < n; ++d) {
    EXPECT_EQ(snap.mechanics->pore_volume[d], pore[d]) << "domain " << d;
    EXPECT_EQ(snap.mechanics->apparent_volume[d], apparent[d]) << "domain " << d;
    moved += pore[d] != detected.pore_volume[d];
  }
  EXPECT_GT(moved, n / 2) << "the particles must have moved for the test to mean anything";
}

// A resume between two flow updates (flow every 4 DEM steps, a sample every step) samples the
// same mass-balance error as the uninterrupted run: the fluid books travel in the snapshot.
TEST(Effects, ResumeBetweenFlowUpdatesSamplesTheSameSeries) {
  SceneSpec scene = BoxedLatticeScene(8, 6);
  for (EffectSpec& e : scene.effects) {
    if (auto* flow = std::get_if<FlowEffectSpec>(&e)) flow->every_steps = 4;
  }
  scene.solver.progress_every = 1;
  scene.solver.end_time_s = 2e-4;

  Simulation reference = MustCreate(scene);
  MustRun(reference);
  const SimulationSnapshot expected = reference.TakeSnapshot();
  ASSERT_GT(reference.step(), 12u);

  Simulation first = MustCreate(scene);
  std::stop_source stop;
  RunControl control;
  control.stop = stop.get_token();
  control.at_step_end = [&](const Simulation& s) {
    if (s.step() == 10) stop.request_stop();  // two steps after the update at step 8
  };
  ASSERT_EQ(first.Run(control).code(), StatusCode::kCancelled);
  const SimulationSnapshot mid = first.TakeSnapshot();
  ASSERT_GT(mid.step_mass_balance_error, 0.0) << "the update at step 8 must have an error to carry";

  Simulation resumed = MustCreate(scene);
  const Status restored = resumed.Restore(mid);
  ASSERT_TRUE(restored.ok()) << restored.message();
  MustRun(resumed);
  EXPECT_TRUE(BitEqual(resumed.TakeSnapshot().series.values, expected.series.values));
}

// Every listed effect is timed, in the canonical order after the integration, and the split adds
// up to no more than the run's wall time.
TEST(Effects, EffectSecondsCoverEveryListedEffect) {
  const SceneSpec scene = BoxedLatticeScene(10, 8);
  Simulation sim = MustCreate(scene);
  const auto t0 = std::chrono::steady_clock::now();
  MustRun(sim);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto split = sim.stepper().EffectSeconds();
  ASSERT_EQ(split.size(), scene.effects.size() + 1);
  EXPECT_EQ(split.front().first, "integration");
  double total = 0.0;
  for (const auto& [name, seconds] : split) {
    EXPECT_GT(seconds, 0.0) << name;
    total += seconds;
  }
  EXPECT_LE(total, wall);
  const auto force = sim.stepper().HookList(kForceHook);
  EXPECT_EQ(split[1].first, force.front());  // contacts leads
}

}  // namespace
}  // namespace seep::core
