// EndingSlot: one worker's companion thread, which records the end of the worker's last job
// (its final checkpoint, result series and outcome: mostly waits on fsync) while the worker
// claims and runs its next one. It holds one ending at a time: Hand waits for the previous one,
// so a worker is never more than one job ahead of what is stored, and the memory of one extra
// finished simulation per worker is the most it costs. The destructor records what is pending
// before it joins, so a stopping runner loses no finished job.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace seep::service {

class EndingSlot {
 public:
  EndingSlot();
  ~EndingSlot();
  EndingSlot(const EndingSlot&) = delete;
  EndingSlot& operator=(const EndingSlot&) = delete;

  // Runs `ending` on the slot's thread, once the previous ending has run.
  void Hand(std::function<void()> ending);
  // Returns once nothing is pending or running.
  void Drain();

 private:
  void Loop(const std::stop_token& stop);

  std::mutex mutex_;
  std::condition_variable_any changed_;
  // Guarded by mutex_; held until it has run, so that empty means the slot is free (the slot's
  // thread runs it unlocked: no one else touches it while it is set).
  std::function<void()> pending_;
  std::jthread thread_;  // last: it starts once the members above exist
};

}  // namespace seep::service
