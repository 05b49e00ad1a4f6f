#include "jobs/ending_slot.h"

namespace seep::service {

EndingSlot::EndingSlot() : thread_([this](const std::stop_token& stop) { Loop(stop); }) {}

EndingSlot::~EndingSlot() {
  Drain();
  thread_.request_stop();
  changed_.notify_all();
  thread_.join();
}

void EndingSlot::Hand(std::function<void()> ending) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !pending_; });
  pending_ = std::move(ending);
  changed_.notify_all();
}

void EndingSlot::Drain() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return !pending_; });
}

void EndingSlot::Loop(const std::stop_token& stop) {
  std::unique_lock lock(mutex_);
  for (;;) {
    // A stop is asked for only after Drain, so nothing pending is dropped.
    if (!changed_.wait(lock, stop, [&] { return static_cast<bool>(pending_); })) return;
    lock.unlock();
    pending_();
    lock.lock();
    pending_ = nullptr;  // its captures (the finished simulation) go before the slot frees
    changed_.notify_all();
  }
}

}  // namespace seep::service
