// Issue 19's "no per-step allocation": once a coupled scene is warm, a step that changes no
// topology (no pair-table rebuild, no re-detection, no bond break) takes nothing from the heap.
// Its own executable: it replaces the global operator new to count what the steps ask for.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>
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

void* Allocate(std::size_t size) {
  Count();
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}

void* AllocateAligned(std::size_t size, std::align_val_t align) {
  Count();
  const auto a = static_cast<std::size_t>(align);
  // aligned_alloc wants a multiple of the alignment.
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a + (size == 0 ? a : 0))) return p;
  throw std::bad_alloc();
}

}  // namespace

// Every replaceable form, so that each allocation is counted and freed by its own pair
// (AddressSanitizer checks that new and delete match).
void* operator new(std::size_t size) { return Allocate(size); }
void* operator new[](std::size_t size) { return Allocate(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return Allocate(size);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return operator new(size, tag);
}
void* operator new(std::size_t size, std::align_val_t align) {
  return AllocateAligned(size, align);
}
void* operator new[](std::size_t size, std::align_val_t align) {
  return AllocateAligned(size, align);
}
void* operator new(std::size_t size, std::align_val_t align, const std::nothrow_t&) noexcept {
  try {
    return AllocateAligned(size, align);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, std::align_val_t align, const std::nothrow_t& tag) noexcept {
  return operator new(size, align, tag);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

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

}  // namespace
}  // namespace seep::core::effects_test
