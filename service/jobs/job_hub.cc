#include "job_hub.h"

namespace seep::service {

void JobHub::Publish(const std::string& id, const JobProgress& progress) {
  {
    std::lock_guard lock(mutex_);
    live_[id] = progress;
    ++version_;
  }
  changed_.notify_all();
}

void JobHub::Finished(const std::string& id) {
  {
    std::lock_guard lock(mutex_);
    live_.erase(id);
    ++version_;
  }
  changed_.notify_all();
}

void JobHub::NotifyChanged() {
  {
    std::lock_guard lock(mutex_);
    ++version_;
  }
  changed_.notify_all();
}

void JobHub::Close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
    ++version_;
  }
  changed_.notify_all();
}

std::optional<JobProgress> JobHub::Live(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = live_.find(id);
  if (it == live_.end()) return std::nullopt;
  return it->second;
}

std::uint64_t JobHub::version() const {
  std::lock_guard lock(mutex_);
  return version_;
}

bool JobHub::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

void JobHub::WaitForChange(std::uint64_t seen, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return version_ != seen || closed_; });
}

}  // namespace seep::service
