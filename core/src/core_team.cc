#include "core_team.h"

#include <pthread.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace seep::core::internal {

namespace {

inline void CpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#else
  std::atomic_signal_fence(std::memory_order_seq_cst);
#endif
}

// Threads of every team of the process (callers and workers), against the cores.
std::atomic<int> g_team_threads{0};
const int g_cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

// How long a wait spins before it sleeps. About 2 ms of pause instructions (20 ns each on the
// VM's EPYC) while the teams fit the cores: a worker then idles through the serial stretches of
// a step (a re-detection of the 10k-disk fracturing bed is 7 ms, and then one wake is nothing
// beside it). More team threads than cores (libgomp throttles the same way): a few spins, since
// the thread waited for may be waiting for this core.
int Spins() { return g_team_threads.load(std::memory_order_relaxed) <= g_cores ? 1 << 17 : 1 << 6; }

// Waits until `done(value)` holds for the value of `word`, and returns that value: spinning, then
// sleeping on the word (a futex), which its writers wake with notify_all (no system call while
// nobody sleeps: libstdc++ counts the sleepers). Not yielding in a loop: a member that waits long
// waits for a thread the host has descheduled, and on a VM a vCPU that keeps yielding keeps the
// host busy with it (the 99,000-disk DEM bench on two threads lost 8 %, 400,000 yields in 2,000
// steps).
template <class Word, class Done>
Word WaitOn(const std::atomic<Word>& word, Done&& done) {
  const int spins = Spins();
  Word value = word.load(std::memory_order_acquire);
  for (int spin = 0; !done(value) && spin < spins; ++spin) {
    CpuRelax();
    value = word.load(std::memory_order_acquire);
  }
  while (!done(value)) {
    word.wait(value, std::memory_order_acquire);
    value = word.load(std::memory_order_acquire);
  }
  return value;
}

// True on a worker always, and on a caller during its run: a run started from there is nested.
thread_local bool t_in_run = false;

// Bumped in a forked child, whose copy of a pool has no worker threads: it must not be used.
std::atomic<unsigned> g_fork_epoch{0};

void AfterForkInChild() { g_fork_epoch.fetch_add(1, std::memory_order_relaxed); }

}  // namespace

class TeamPool {
 public:
  explicit TeamPool(int requested) : requested_(requested) {
    epoch_ = g_fork_epoch.load(std::memory_order_relaxed);
    workers_.reserve(static_cast<std::size_t>(requested - 1));
    try {
      for (int index = 1; index < requested; ++index) {
        workers_.emplace_back([this, index] { WorkerLoop(index); });
      }
    } catch (const std::system_error&) {
      // No more threads: the team is the caller and the workers made so far.
    }
    members_ = static_cast<int>(workers_.size()) + 1;
    g_team_threads.fetch_add(members_, std::memory_order_relaxed);
  }

  ~TeamPool() {
    stop_ = true;
    start_.fetch_add(1, std::memory_order_release);
    start_.notify_all();
    for (std::thread& worker : workers_) worker.join();
    g_team_threads.fetch_sub(members_, std::memory_order_relaxed);
  }

  TeamPool(const TeamPool&) = delete;
  TeamPool& operator=(const TeamPool&) = delete;

  int requested() const { return requested_; }
  unsigned epoch() const { return epoch_; }

  void Run(TeamBody body, void* context) {
    body_ = body;
    context_ = context;
    finished_.store(0, std::memory_order_relaxed);
    // Release: the workers that see the new generation see the body and the reset count.
    start_.fetch_add(1, std::memory_order_release);
    start_.notify_all();  // a system call only when a worker sleeps (libstdc++ counts waiters)
    std::exception_ptr failure;
    t_in_run = true;
    try {
      body(context, TeamMember(this, 0, members_));
    } catch (...) {
      failure = std::current_exception();
    }
    t_in_run = false;
    // Acquire: what the workers wrote is visible to the caller after the run.
    WaitOn(finished_, [&](int finished) { return finished == members_ - 1; });
    if (failure) std::rethrow_exception(failure);
  }

  void Barrier(int size) {
    const std::uint32_t generation = barrier_.load(std::memory_order_acquire);
    // acq_rel: the last to arrive has seen every member's writes, and releases them all below.
    if (arrived_.fetch_add(1, std::memory_order_acq_rel) == size - 1) {
      arrived_.store(0, std::memory_order_relaxed);
      barrier_.store(generation + 1, std::memory_order_release);
      barrier_.notify_all();
      return;
    }
    WaitOn(barrier_, [&](std::uint32_t now) { return now != generation; });
  }

 private:
  void WorkerLoop(int index) {
    t_in_run = true;
    std::uint32_t seen = 0;
    for (;;) {
      seen = WaitOn(start_, [&](std::uint32_t now) { return now != seen; });
      if (stop_) return;
      body_(context_, TeamMember(this, index, members_));
      finished_.fetch_add(1, std::memory_order_release);
      finished_.notify_all();
    }
  }

  const int requested_;
  int members_ = 1;
  unsigned epoch_ = 0;
  std::vector<std::thread> workers_;
  // Written by the caller between runs only; read by the workers after they acquire start_.
  TeamBody body_ = nullptr;
  void* context_ = nullptr;
  bool stop_ = false;
  // Each on its own cache line: the caller spins on one while the workers write another.
  alignas(64) std::atomic<std::uint32_t> start_{0};
  alignas(64) std::atomic<int> finished_{0};
  alignas(64) std::atomic<int> arrived_{0};
  alignas(64) std::atomic<std::uint32_t> barrier_{0};
};

void TeamMember::Barrier() const {
  if (pool_ != nullptr && size_ > 1) pool_->Barrier(size_);
}

void RunTeam(int members, TeamBody body, void* context) {
  if (members <= 1 || t_in_run) {
    body(context, TeamMember::Solo());
    return;
  }
  static std::once_flag fork_handler;
  std::call_once(fork_handler, [] { pthread_atfork(nullptr, nullptr, AfterForkInChild); });
  thread_local std::unique_ptr<TeamPool> pool;
  if (pool != nullptr && pool->epoch() != g_fork_epoch.load(std::memory_order_relaxed)) {
    // A forked child's copy: its workers do not exist in this process, so it cannot be joined.
    (void)pool.release();
  }
  if (pool == nullptr || pool->requested() != members) {
    pool.reset();
    pool = std::make_unique<TeamPool>(members);
  }
  pool->Run(body, context);
}

}  // namespace seep::core::internal
