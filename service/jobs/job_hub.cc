#include "job_hub.h"

namespace seep::service {

JobHub::Channel& JobHub::ChannelLocked(const std::string& id) {
  std::shared_ptr<Channel>& channel = channels_[id];
  if (!channel) channel = std::make_shared<Channel>();
  return *channel;
}

void JobHub::ForgetIfUnusedLocked(const std::string& id) {
  const auto it = channels_.find(id);
  if (it != channels_.end() && it->second->followers == 0 && !it->second->live) {
    channels_.erase(it);
  }
}

void JobHub::Publish(const std::string& id, const JobProgress& progress) {
  std::lock_guard lock(mutex_);
  Channel& channel = ChannelLocked(id);
  channel.live = progress;
  channel.versions.progress = ++sequence_;
  channel.changed.notify_all();
}

void JobHub::Finished(const std::string& id) {
  std::lock_guard lock(mutex_);
  const auto it = channels_.find(id);
  if (it == channels_.end()) return;  // nobody follows it and it has no live progress
  it->second->live.reset();
  it->second->versions.record = ++sequence_;
  it->second->changed.notify_all();
  ForgetIfUnusedLocked(id);
}

void JobHub::RecordChanged(const std::string& id) {
  std::lock_guard lock(mutex_);
  const auto it = channels_.find(id);
  if (it == channels_.end()) return;
  it->second->versions.record = ++sequence_;
  it->second->changed.notify_all();
}

void JobHub::Close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  for (auto& [id, channel] : channels_) channel->changed.notify_all();
}

std::optional<JobHub::Follower> JobHub::Follow(const std::string& id, int max_followers) {
  std::lock_guard lock(mutex_);
  if (max_followers > 0 && followers_ >= max_followers) return std::nullopt;
  std::shared_ptr<Channel>& channel = channels_[id];
  if (!channel) channel = std::make_shared<Channel>();
  ++channel->followers;
  ++followers_;
  return Follower(this, id, channel);
}

JobHub::Follower::~Follower() {
  if (!channel_) return;  // moved from
  std::lock_guard lock(hub_->mutex_);
  --channel_->followers;
  --hub_->followers_;
  hub_->ForgetIfUnusedLocked(id_);
}

JobHub::Versions JobHub::Follower::versions() const {
  std::lock_guard lock(hub_->mutex_);
  return channel_->versions;
}

std::optional<JobProgress> JobHub::Follower::live() const {
  std::lock_guard lock(hub_->mutex_);
  return channel_->live;
}

JobHub::Versions JobHub::Follower::WaitForChange(Versions seen,
                                                 std::chrono::milliseconds timeout) const {
  std::unique_lock lock(hub_->mutex_);
  channel_->changed.wait_for(lock, timeout,
                             [&] { return channel_->versions != seen || hub_->closed_; });
  return channel_->versions;
}

std::optional<JobProgress> JobHub::Live(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto it = channels_.find(id);
  if (it == channels_.end()) return std::nullopt;
  return it->second->live;
}

bool JobHub::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

int JobHub::followers() const {
  std::lock_guard lock(mutex_);
  return followers_;
}

}  // namespace seep::service
