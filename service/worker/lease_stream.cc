#include "worker/lease_stream.h"

#include <utility>

#include "worker/remote_ledger.h"

namespace seep::service {
namespace {

// How long the destructor waits for seepd to end a stream it did not close itself.
constexpr std::chrono::seconds kCloseTimeout{10};

}  // namespace

LeaseStream::LeaseStream(v1::WorkerService::Stub& stub, std::unique_ptr<grpc::ClientContext> ctx,
                         v1::LeaseRef lease)
    : ctx_(std::move(ctx)),
      stream_(stub.KeepLease(ctx_.get())),
      lease_(std::move(lease)),
      reader_done_(reader_end_.get_future()) {
  reader_ = std::thread([this] {
    v1::LeaseNews news;
    while (stream_->Read(&news)) {
      if (news.cancel_requested()) cancel_requested_ = true;
    }
    reader_end_.set_value();
  });
}

LeaseStream::~LeaseStream() {
  (void)Close(kCloseTimeout);
  reader_.join();
}

core::Status LeaseStream::Finished() {
  if (!final_) {
    reader_done_.wait();
    final_ = FromGrpcStatus("KeepLease", stream_->Finish());
    // A stream that ended OK before the worker closed it was not ended by the worker: seepd went
    // away cleanly (its shutdown). The lease is no longer kept.
    if (final_->ok() && !writes_done_) {
      final_ = core::Unavailable("WorkerService.KeepLease: seepd ended the stream");
    }
  }
  return *final_;
}

core::Result<bool> LeaseStream::Beat(std::uint32_t lease_ms, const v1::Progress* progress) {
  std::lock_guard lock(write_mutex_);
  if (writes_done_) {
    return core::FailedPrecondition("WorkerService.KeepLease: the stream was closed");
  }
  if (!ReadEnded()) {
    v1::LeaseBeat beat;
    *beat.mutable_lease() = lease_;
    beat.set_lease_ms(lease_ms);
    if (progress != nullptr) *beat.mutable_progress() = *progress;
    // A failed write means the stream ended: its status says why.
    if (stream_->Write(beat)) return cancel_requested_.load();
  }
  return Finished();
}

core::Status LeaseStream::Close(std::chrono::milliseconds timeout) {
  std::lock_guard lock(write_mutex_);
  if (final_) return *final_;
  if (!writes_done_ && !ReadEnded()) stream_->WritesDone();
  writes_done_ = true;
  if (reader_done_.wait_for(timeout) != std::future_status::ready) ctx_->TryCancel();
  return Finished();
}

}  // namespace seep::service
