// JobHub: the in-memory side of job progress. Workers publish live progress here many times a
// second; the store only gets a throttled copy. Each job has its own channel (its live progress,
// two change counters and a condition variable), so a job's progress wakes the streams that
// follow that job and no other. A channel lives while the job runs or someone follows it.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "store/job_record.h"

namespace seep::service {

class JobHub {
  struct Channel;

 public:
  // What a follower has seen of one job: when its stored record last changed (state, cancel
  // request, outcome) and when its live progress last did. Values come from one hub-wide
  // sequence, so a channel made again never repeats an earlier value.
  struct Versions {
    std::uint64_t record = 0;
    std::uint64_t progress = 0;
    bool operator==(const Versions&) const = default;
  };

  // Keeps one job's channel while a stream follows the job (WatchJob); every change made while
  // it exists is seen by WaitForChange. Movable, not copyable.
  class Follower {
   public:
    Follower(Follower&&) noexcept = default;
    Follower& operator=(Follower&&) noexcept = default;
    ~Follower();
    Versions versions() const;
    std::optional<JobProgress> live() const;
    // Waits until the job's versions differ from `seen`, the hub closes or the timeout passes;
    // returns the versions now.
    Versions WaitForChange(Versions seen, std::chrono::milliseconds timeout) const;

   private:
    friend class JobHub;
    Follower(JobHub* hub, std::string id, std::shared_ptr<Channel> channel)
        : hub_(hub), id_(std::move(id)), channel_(std::move(channel)) {}
    JobHub* hub_;
    std::string id_;
    std::shared_ptr<Channel> channel_;
  };

  // Live progress of a running job (its progress version moves).
  void Publish(const std::string& id, const JobProgress& progress);
  // The job left RUNNING (or was taken from this worker): its live progress is dropped and its
  // record version moves.
  void Finished(const std::string& id);
  // The job's stored record changed otherwise (claimed, cancel requested, resumed).
  void RecordChanged(const std::string& id);
  // Ends every wait: the server is shutting down.
  void Close();

  // Follows a job; nullopt when max_followers streams (> 0) follow jobs already.
  std::optional<Follower> Follow(const std::string& id, int max_followers = 0);
  std::optional<JobProgress> Live(const std::string& id) const;
  bool closed() const;
  // Streams following a job now (for the metrics).
  int followers() const;

 private:
  struct Channel {
    std::optional<JobProgress> live;
    Versions versions;
    int followers = 0;
    std::condition_variable changed;
  };
  // The job's channel, made if missing (mutex_ held).
  Channel& ChannelLocked(const std::string& id);
  // Drops a channel nobody needs any more (mutex_ held).
  void ForgetIfUnusedLocked(const std::string& id);

  mutable std::mutex mutex_;
  std::uint64_t sequence_ = 0;
  bool closed_ = false;
  int followers_ = 0;
  std::map<std::string, std::shared_ptr<Channel>> channels_;
};

}  // namespace seep::service
