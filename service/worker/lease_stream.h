// LeaseStream: seep-worker's end of one running job's WorkerService.KeepLease stream. Beats
// (lease renewals, with progress when there is some) are written without waiting for an answer;
// a reader thread takes seepd's news (a pending cancel) and notices the stream's end. A beat
// refused by seepd ends the stream: the next Beat returns that status (ABORTED: the lease was
// lost), as the unary Heartbeat would have one beat earlier. Thread-safe: the runner's
// heartbeat thread and the job's progress reports may beat at once.
#pragma once

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "seep/core/status.h"
#include "seep/v1/worker_service.grpc.pb.h"

namespace seep::service {

class LeaseStream {
 public:
  // Opens the stream with `ctx` (the token set, no deadline: it lasts as long as the job).
  LeaseStream(v1::WorkerService::Stub& stub, std::unique_ptr<grpc::ClientContext> ctx,
              v1::LeaseRef lease);
  ~LeaseStream();  // Close(), waiting at most close_timeout
  LeaseStream(const LeaseStream&) = delete;
  LeaseStream& operator=(const LeaseStream&) = delete;

  // One beat: the lease extended by lease_ms, and `progress` stored when given. True when seepd
  // said a cancel of the job is pending; the stream's status once it has ended.
  core::Result<bool> Beat(std::uint32_t lease_ms, const v1::Progress* progress);
  // Ends the stream (WritesDone) and waits, at most `timeout`, for seepd to end it: every beat
  // written was then handled. The stream's status (cancelled when seepd did not answer in time).
  core::Status Close(std::chrono::milliseconds timeout);
  std::int64_t lease_epoch() const { return lease_.lease_epoch(); }

 private:
  bool ReadEnded() const {
    return reader_done_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  }
  // The status the stream ended with (called with write_mutex_ held, once reading has ended).
  core::Status Finished();

  std::unique_ptr<grpc::ClientContext> ctx_;
  std::unique_ptr<grpc::ClientReaderWriter<v1::LeaseBeat, v1::LeaseNews>> stream_;
  v1::LeaseRef lease_;
  std::mutex write_mutex_;
  std::atomic<bool> cancel_requested_{false};
  std::promise<void> reader_end_;
  std::future<void> reader_done_;  // ready once the reader saw the stream's end
  std::thread reader_;
  bool writes_done_ = false;           // guarded by write_mutex_
  std::optional<core::Status> final_;  // guarded by write_mutex_
};

}  // namespace seep::service
