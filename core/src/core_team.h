// The core's thread team: the calling thread and core-threads - 1 workers that it keeps, which
// run one body each and meet at barriers.
//
// Why not OpenMP regions: libgomp ends every barrier, the dock that starts a region and the team
// barrier that ends it, with a futex wake system call, even when every thread is spinning and
// none sleeps. On the 2-core VM a futex call costs 1 us, an empty region of two 3 us, a barrier
// 1.6 us; a coupled step of the settled bed opened 22 regions, and start, end and the waits they
// add took about 90 us of its 600 us on two threads. This team's workers spin on a generation
// word and sleep only after about 2 ms without work (a run then pays one wake), so starting and
// ending a run costs two cache-line transfers and no system call: 0.5 us on the VM.
//
// Results never depend on the team: every parallel loop of the core writes per-item results, or
// sums whole numbers, whatever the shares (parallel_threshold.h).
#pragma once

#include <cstddef>
#include <memory>
#include <type_traits>
#include <utility>

namespace seep::core::internal {

class TeamPool;

// One member's view of a run: its index in [0, size), and the team's barrier.
class TeamMember {
 public:
  // A team of one: the calling thread alone (no pool, Barrier does nothing).
  static TeamMember Solo() { return TeamMember(nullptr, 0, 1); }

  int index() const { return index_; }
  int size() const { return size_; }

  // This member's share of `n` items, [first, second): contiguous, in member order, of sizes
  // that differ by one at most.
  std::pair<std::ptrdiff_t, std::ptrdiff_t> Share(std::ptrdiff_t n) const {
    return {n * index_ / size_, n * (index_ + 1) / size_};
  }

  // Returns once every member of the run has called it; what any member wrote before is then
  // visible to all.
  void Barrier() const;

 private:
  friend class TeamPool;
  TeamMember(TeamPool* pool, int index, int size) : pool_(pool), index_(index), size_(size) {}

  TeamPool* pool_;
  int index_;
  int size_;
};

using TeamBody = void (*)(void* context, const TeamMember& member);

// Runs body(context, member) once for each member of a team of `members` threads (member 0 is
// the calling thread) and returns when all have returned. A team of one, or a call from inside
// a run (a nested one), runs the body on the calling thread alone. The workers belong to the
// calling thread and last until it ends (or the team size changes). The body must not throw on
// a worker; an exception on the calling thread is rethrown once the workers have finished.
void RunTeam(int members, TeamBody body, void* context);

template <class Body>
void RunOnTeam(int members, Body&& body) {
  using Callable = std::remove_reference_t<Body>;
  RunTeam(
      members,
      [](void* context, const TeamMember& member) { (*static_cast<Callable*>(context))(member); },
      const_cast<void*>(static_cast<const void*>(std::addressof(body))));
}

}  // namespace seep::core::internal
