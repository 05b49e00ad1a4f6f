// Issue 19's "no per-step allocation": once a coupled scene is warm, a step that changes no
// topology (no pair-table rebuild, no re-detection, no bond break) takes nothing from the heap.
// Its own executable: it replaces malloc and its kin to count what the steps ask for.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <stop_token>
#include <variant>

#include "coupled_scenes.h"

namespace {

std::atomic<bool> counting{false};
std::atomic<std::uint64_t> allocations{0};

void Count() {
  if (counting.load(std::memory_order_relaxed)) {
    allocations.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace

// Every allocation of the process reaches malloc and its kin: operator new (libstdc++'s calls
// malloc) as much as Eigen's aligned_malloc, CHOLMOD's and libgomp's. Without a sanitizer they are
// replaced here and forward to glibc's own entry points; under AddressSanitizer, whose allocator
// serves them all, its allocation hook counts instead.
#if defined(__SANITIZE_ADDRESS__)
// Declared here as in <sanitizer/allocator_interface.h>, which Debian's GCC does not install.
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*,
                                                                             std::size_t),
                                                         void (*free_hook)(const volatile void*));

namespace {
void CountHook(const volatile void*, std::size_t) { Count(); }
void IgnoreFree(const volatile void*) {}
[[maybe_unused]] const int kHooksInstalled =
    __sanitizer_install_malloc_and_free_hooks(CountHook, IgnoreFree);
}  // namespace
#else
#include <cerrno>

extern "C" {
void* __libc_malloc(std::size_t size) noexcept;
void __libc_free(void* p) noexcept;
void* __libc_calloc(std::size_t count, std::size_t size) noexcept;
void* __libc_realloc(void* p, std::size_t size) noexcept;
void* __libc_memalign(std::size_t alignment, std::size_t size) noexcept;

void* malloc(std::size_t size) noexcept {
  Count();
  return __libc_malloc(size);
}
void free(void* p) noexcept { __libc_free(p); }
void* calloc(std::size_t count, std::size_t size) noexcept {
  Count();
  return __libc_calloc(count, size);
}
void* realloc(void* p, std::size_t size) noexcept {
  Count();
  return __libc_realloc(p, size);
}
void* memalign(std::size_t alignment, std::size_t size) noexcept {
  Count();
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
  Count();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
  Count();
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
}  // extern "C"
#endif

namespace seep::core::effects_test {
namespace {

struct Window {
  std::uint64_t allocations = 0;
  EffectCounters before, after;
};

// Runs `scene` for `warmup` steps, then counts the heap allocations of the next `steps` steps
// (the stepper's loop and every effect, on the threads the process has).
Window CountAllocations(const SceneSpec& scene, std::uint64_t warmup, std::uint64_t steps) {
  Simulation sim = MustCreate(scene);
  Window w;
  std::stop_source stop;
  RunControl control;
  control.stop = stop.get_token();
  control.at_step_end = [&](const Simulation& s) {
    if (s.step() == warmup) {
      w.before = s.stepper().state().counters;
      allocations = 0;
      counting = true;
    } else if (s.step() == warmup + steps) {
      counting = false;
      w.allocations = allocations;
      w.after = s.stepper().state().counters;
      stop.request_stop();
    }
  };
  EXPECT_EQ(sim.Run(control).code(), StatusCode::kCancelled);
  counting = false;
  return w;
}

// The instrument: what a step could allocate through is counted (operator new, Eigen's vectors,
// C's malloc as CHOLMOD calls it).
TEST(StepAllocation, TheCountSeesNewEigenAndMalloc) {
  void* (*const volatile c_malloc)(std::size_t) = std::malloc;
  allocations = 0;
  counting = true;
  auto* ints = new int[4];
  Eigen::VectorXd vector(100);
  void* block = c_malloc(64);
  counting = false;
  const std::uint64_t seen = allocations;
  std::free(block);
  delete[] ints;
  EXPECT_EQ(vector.size(), 100);
  EXPECT_EQ(seen, 3u);
}

// The hydraulic-fracturing sample (bonded, four servo walls drained at 0 Pa, injection, the
// explicit flow with every coupling effect and re-detection): the coupled bench's scene.
// The series sample (every solver.progress_every steps) appends a row and is left out of the
// window; a step between samples is what every step of a run is.
TEST(StepAllocation, AWarmCoupledStepTakesNothingFromTheHeap) {
  SceneSpec scene = HydrofracScene(1e5, 1e7);
  scene.solver.progress_every = 1000;
  // A flow update at every DEM step (automatic would update every few): every step of the
  // window runs every coupling effect.
  for (EffectSpec& effect : scene.effects) {
    if (auto* flow = std::get_if<FlowEffectSpec>(&effect)) flow->every_steps = 1;
  }
  const Window w = CountAllocations(scene, 50, 200);
  // The window's premise: the steps were coupled, and changed no topology.
  EXPECT_EQ(w.after.flow_updates - w.before.flow_updates, 200u);
  EXPECT_EQ(w.after.volume_updates - w.before.volume_updates, 200u);
  EXPECT_EQ(w.after.aperture_updates - w.before.aperture_updates, 200u);
  EXPECT_EQ(w.after.pressure_force_passes - w.before.pressure_force_passes, 200u);
  EXPECT_EQ(w.after.redetections, w.before.redetections);
  EXPECT_EQ(w.after.dem.neighbour_rebuilds, w.before.dem.neighbour_rebuilds);
  EXPECT_EQ(w.allocations, 0u);
}

// The same sample with the implicit flow on CHOLMOD's supernodal factorization (the default), as
// the Terzaghi column runs: every step assembles, refactorizes (replayed, see
// supernodal_refactorization.h) and solves its pressure system; the solve's dense arrays, the
// capacities, the critical step and the right-hand side are kept from step to step.
TEST(StepAllocation, AWarmImplicitCoupledStepTakesNothingFromTheHeap) {
  SceneSpec scene = HydrofracScene(1e5, 1e7);
  scene.solver.progress_every = 1000;
  scene.solver.kind = SolverKind::kImplicit;
  ASSERT_EQ(scene.solver.linear_solver, LinearSolverKind::kCholmodSupernodal);
  for (EffectSpec& effect : scene.effects) {
    if (auto* flow = std::get_if<FlowEffectSpec>(&effect)) flow->every_steps = 1;
  }
  const Window w = CountAllocations(scene, 50, 200);
  EXPECT_EQ(w.after.flow_updates - w.before.flow_updates, 200u);
  EXPECT_EQ(w.after.redetections, w.before.redetections);
  EXPECT_EQ(w.after.dem.neighbour_rebuilds, w.before.dem.neighbour_rebuilds);
  EXPECT_EQ(w.allocations, 0u);
}

}  // namespace
}  // namespace seep::core::effects_test
