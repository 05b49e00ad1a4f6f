#include "jobs/physics_pool.h"

#include <algorithm>
#include <stdexcept>

#include "seep/core/threads.h"

namespace seep::service {

PhysicsPool::PhysicsPool(int threads, int core_threads, std::size_t max_waiting)
    : core_threads_(std::max(1, core_threads)), max_waiting_(max_waiting) {
  for (int i = 0; i < std::max(1, threads); ++i) {
    threads_.emplace_back([this](const std::stop_token& stop) { Loop(stop); });
  }
}

PhysicsPool::~PhysicsPool() {
  for (auto& t : threads_) t.request_stop();
  wake_.notify_all();
  threads_.clear();  // joins
  // Nobody runs what still waits: wake its callers with an error.
  for (const auto& ticket : waiting_) {
    std::lock_guard lock(ticket->mutex_);
    if (ticket->state_ != Ticket::State::kWaiting) continue;
    ticket->state_ = Ticket::State::kDone;
    ticket->error_ = std::make_exception_ptr(std::runtime_error("the physics pool stopped"));
    ticket->done_.notify_all();
  }
}

std::shared_ptr<PhysicsPool::Ticket> PhysicsPool::Post(std::function<void()> task) {
  std::shared_ptr<Ticket> ticket(new Ticket(std::move(task)));
  {
    std::lock_guard lock(mutex_);
    // Abandoned tickets hold no place in the queue.
    std::erase_if(waiting_, [](const std::shared_ptr<Ticket>& t) {
      std::lock_guard ticket_lock(t->mutex_);
      return t->state_ == Ticket::State::kAbandoned;
    });
    if (waiting_.size() >= max_waiting_) return nullptr;
    waiting_.push_back(ticket);
  }
  wake_.notify_one();
  return ticket;
}

std::uint64_t PhysicsPool::tasks_run() const {
  std::lock_guard lock(mutex_);
  return tasks_run_;
}

void PhysicsPool::Loop(const std::stop_token& stop) {
  core::SetCoreThreadsForThisThread(core_threads_);
  while (true) {
    std::shared_ptr<Ticket> ticket;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, stop, [this] { return !waiting_.empty(); });
      if (stop.stop_requested()) return;
      ticket = std::move(waiting_.front());
      waiting_.pop_front();
    }
    {
      std::lock_guard lock(ticket->mutex_);
      if (ticket->state_ == Ticket::State::kAbandoned) continue;
      ticket->state_ = Ticket::State::kRunning;
    }
    std::exception_ptr error;
    try {
      ticket->task_();
    } catch (...) {
      error = std::current_exception();
    }
    ticket->task_ = nullptr;  // what it captured goes now, not with the last reference
    {
      std::lock_guard lock(mutex_);
      ++tasks_run_;
    }
    std::lock_guard lock(ticket->mutex_);
    ticket->state_ = Ticket::State::kDone;
    ticket->error_ = error;
    ticket->done_.notify_all();
  }
}

bool PhysicsPool::Ticket::WaitFor(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  if (!done_.wait_for(lock, timeout, [this] { return state_ == State::kDone; })) return false;
  if (error_) std::rethrow_exception(error_);
  return true;
}

void PhysicsPool::Ticket::Abandon() {
  std::lock_guard lock(mutex_);
  if (state_ == State::kWaiting) state_ = State::kAbandoned;
}

}  // namespace seep::service
