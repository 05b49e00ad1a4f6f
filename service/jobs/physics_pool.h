// PhysicsPool: the threads on which RPC handlers run physics (GetJobFields rebuilds a job's
// network and restores a checkpoint), so that a gRPC handler thread never does, and so that the
// core's parallel loops there use a job's thread budget (seepd --threads-per-job, as the
// workers' jobs do) instead of OpenMP's default of every core.
//
// Bounded: `threads` tasks run at once and at most `max_waiting` more wait; Post refuses the
// rest. A caller that stops waiting (its call was cancelled or ran past its deadline) abandons
// its ticket: a task that has not started then never starts; one that has started runs to its
// end, and its result is dropped.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace seep::service {

class PhysicsPool {
 public:
  class Ticket;

  PhysicsPool(int threads, int core_threads, std::size_t max_waiting);
  // Starts no more tasks (waiting ones are failed) and joins the threads.
  ~PhysicsPool();
  PhysicsPool(const PhysicsPool&) = delete;
  PhysicsPool& operator=(const PhysicsPool&) = delete;

  // Queues `task`; nullptr when max_waiting tasks already wait.
  std::shared_ptr<Ticket> Post(std::function<void()> task);

  // The thread count of the core's parallel loops in every task (>= 1).
  int core_threads() const { return core_threads_; }
  // Tasks run to their end so far.
  std::uint64_t tasks_run() const;

 private:
  void Loop(const std::stop_token& stop);

  int core_threads_;
  std::size_t max_waiting_;
  mutable std::mutex mutex_;
  std::condition_variable_any wake_;
  std::deque<std::shared_ptr<Ticket>> waiting_;  // guarded by mutex_
  std::uint64_t tasks_run_ = 0;                  // guarded by mutex_
  std::vector<std::jthread> threads_;
};

class PhysicsPool::Ticket {
 public:
  // Waits up to `timeout` for the task to end; true once it has. Rethrows what the task threw.
  bool WaitFor(std::chrono::milliseconds timeout);
  // The caller no longer waits: the task does not start if it has not yet.
  void Abandon();

 private:
  friend class PhysicsPool;
  enum class State { kWaiting, kRunning, kDone, kAbandoned };
  explicit Ticket(std::function<void()> task) : task_(std::move(task)) {}

  std::mutex mutex_;
  std::condition_variable done_;
  State state_ = State::kWaiting;  // guarded by mutex_
  std::exception_ptr error_;       // guarded by mutex_
  std::function<void()> task_;
};

}  // namespace seep::service
