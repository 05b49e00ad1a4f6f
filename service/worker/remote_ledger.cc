#include "worker/remote_ledger.h"

#include <fmt/format.h>

#include <algorithm>
#include <utility>

#include "codec/job_codec.h"
#include "codec/worker_codec.h"
#include "rpc/status_mapping.h"
#include "store/sha256.h"

namespace seep::service {
namespace {

// Checkpoint transfers carry up to the whole state: longer than a unary call.
constexpr int kTransferTimeoutFactor = 10;
// See RemoteLedger::closed_epochs_.
constexpr std::size_t kClosedLeasesKept = 4096;

void SetLease(const std::string& id, std::int64_t epoch, v1::LeaseRef* out) {
  out->set_job_id(id);
  out->set_lease_epoch(epoch);
}

std::uint32_t LeaseMs(std::chrono::milliseconds lease) {
  return static_cast<std::uint32_t>(std::clamp<std::int64_t>(lease.count(), 0, UINT32_MAX));
}

}  // namespace

core::Status FromGrpcStatus(const char* rpc, const grpc::Status& status) {
  if (status.ok()) return core::Status::Ok();
  const grpc::StatusCode code = status.error_code();
  core::StatusCode mapped = core::StatusCode::kInternal;
  switch (code) {
    case grpc::StatusCode::CANCELLED:
      mapped = core::StatusCode::kCancelled;
      break;
    case grpc::StatusCode::INVALID_ARGUMENT:
      mapped = core::StatusCode::kInvalidArgument;
      break;
    case grpc::StatusCode::NOT_FOUND:
      mapped = core::StatusCode::kNotFound;
      break;
    case grpc::StatusCode::ALREADY_EXISTS:
      mapped = core::StatusCode::kAlreadyExists;
      break;
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      mapped = core::StatusCode::kResourceExhausted;
      break;
    case grpc::StatusCode::FAILED_PRECONDITION:
      mapped = core::StatusCode::kFailedPrecondition;
      break;
    case grpc::StatusCode::ABORTED:
      mapped = core::StatusCode::kAborted;
      break;
    case grpc::StatusCode::OUT_OF_RANGE:
      mapped = core::StatusCode::kOutOfRange;
      break;
    case grpc::StatusCode::UNAVAILABLE:
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      mapped = core::StatusCode::kUnavailable;
      break;
    case grpc::StatusCode::DATA_LOSS:
      mapped = core::StatusCode::kDataLoss;
      break;
    default:
      break;
  }
  return {mapped,
          fmt::format("WorkerService.{}: {}: {}", rpc, GrpcCodeName(code), status.error_message())};
}

RemoteLedger::RemoteLedger(const std::shared_ptr<grpc::Channel>& channel,
                           std::function<void(grpc::ClientContext*)> prepare,
                           std::chrono::milliseconds timeout,
                           std::optional<WorkerPlacement> placement)
    : stub_(v1::WorkerService::NewStub(channel)),
      prepare_(std::move(prepare)),
      timeout_(timeout),
      placement_(std::move(placement)) {}

std::unique_ptr<grpc::ClientContext> RemoteLedger::Context(
    std::chrono::milliseconds timeout) const {
  auto ctx = std::make_unique<grpc::ClientContext>();
  ctx->set_deadline(std::chrono::system_clock::now() + timeout);
  if (prepare_) prepare_(ctx.get());
  return ctx;
}

core::Result<std::optional<JobRecord>> RemoteLedger::Claim(const std::string& owner,
                                                           std::chrono::milliseconds lease) {
  v1::ClaimJobRequest request;
  request.set_worker(owner);
  request.set_lease_ms(LeaseMs(lease));
  if (placement_) {
    request.mutable_placement()->set_system("slurm");
    request.mutable_placement()->set_job_id(placement_->batch_job_id);
    request.mutable_placement()->set_node(placement_->node);
  }
  v1::ClaimJobResponse response;
  SEEP_RETURN_IF_ERROR(
      FromGrpcStatus("ClaimJob", stub_->ClaimJob(Context(timeout_).get(), request, &response)));
  if (!response.has_job()) return std::optional<JobRecord>();
  return std::optional<JobRecord>(LeasedJobFromProto(response.job()));
}

core::Result<bool> RemoteLedger::Beat(const std::string& id, std::int64_t epoch,
                                      std::chrono::milliseconds lease,
                                      const v1::Progress* progress) {
  std::shared_ptr<LeaseStream> stream;
  std::shared_ptr<LeaseStream> replaced;  // of an older epoch: closed outside the lock
  {
    std::lock_guard lock(streams_mutex_);
    if (const auto closed = closed_epochs_.find(id);
        closed != closed_epochs_.end() && closed->second >= epoch) {
      return core::Aborted(fmt::format(
          "WorkerService.KeepLease: the lease of job {} (epoch {}) ended with the job's finish", id,
          epoch));
    }
    std::shared_ptr<LeaseStream>& slot = streams_[id];
    if (slot == nullptr || slot->lease_epoch() != epoch) {
      auto ctx = std::make_unique<grpc::ClientContext>();
      if (prepare_) prepare_(ctx.get());
      v1::LeaseRef ref;
      SetLease(id, epoch, &ref);
      replaced = std::exchange(
          slot, std::make_shared<LeaseStream>(*stub_, std::move(ctx), std::move(ref)));
    }
    stream = slot;
  }
  auto cancel = stream->Beat(LeaseMs(lease), progress);
  if (!cancel.ok()) {
    std::lock_guard lock(streams_mutex_);
    const auto it = streams_.find(id);
    if (it != streams_.end() && it->second == stream) streams_.erase(it);
  }
  return cancel;
}

void RemoteLedger::CloseStream(const std::string& id, std::int64_t epoch) {
  std::shared_ptr<LeaseStream> stream;
  {
    std::lock_guard lock(streams_mutex_);
    if (closed_epochs_.size() >= kClosedLeasesKept) closed_epochs_.clear();
    closed_epochs_[id] = epoch;
    const auto it = streams_.find(id);
    if (it == streams_.end()) return;
    stream = std::move(it->second);
    streams_.erase(it);
  }
  // Its status is the next call's too (a lost lease refuses the finish as it refused a beat).
  (void)stream->Close(timeout_);
}

core::Result<bool> RemoteLedger::Heartbeat(const std::string& id, std::int64_t epoch,
                                           std::chrono::milliseconds lease) {
  return Beat(id, epoch, lease, nullptr);
}

core::Status RemoteLedger::UpdateProgress(const std::string& id, std::int64_t epoch,
                                          const JobProgress& progress) {
  v1::Progress message;
  ProgressToProto(progress, &message);
  // lease 0: progress only; the heartbeats renew the lease.
  return Beat(id, epoch, std::chrono::milliseconds(0), &message).status();
}

core::Status RemoteLedger::AddEvent(const std::string& id, std::int64_t epoch,
                                    const std::string& kind, const std::string& message) {
  v1::AddJobEventRequest request;
  SetLease(id, epoch, request.mutable_lease());
  request.set_kind(kind);
  request.set_message(message);
  v1::AddJobEventResponse response;
  return FromGrpcStatus("AddJobEvent",
                        stub_->AddJobEvent(Context(timeout_).get(), request, &response));
}

core::Result<std::int64_t> RemoteLedger::SaveCheckpoint(const JobRecord& job,
                                                        const CheckpointMeta& meta,
                                                        std::string_view state, std::uint32_t keep,
                                                        CheckpointRole /*role*/) {
  // The coordinator records every uploaded checkpoint durably: its upload says nothing of it.
  auto ctx = Context(timeout_ * kTransferTimeoutFactor);
  v1::UploadCheckpointResponse response;
  auto writer = stub_->UploadCheckpoint(ctx.get(), &response);
  v1::UploadCheckpointRequest head;
  v1::CheckpointUploadStart* start = head.mutable_start();
  SetLease(job.id, job.lease_epoch, start->mutable_lease());
  start->set_build_id(meta.build_id);
  start->set_step(meta.step);
  start->set_time_s(meta.time_s);
  start->set_state_bytes(state.size());
  start->set_state_sha256(Sha256(state));
  start->set_keep(keep);
  // A failed Write means the call ended: Finish says why.
  bool open = writer->Write(head);
  std::uint32_t index = 0;
  for (std::size_t at = 0; open && at < state.size(); at += kCheckpointChunkBytes, ++index) {
    v1::UploadCheckpointRequest piece;
    piece.mutable_chunk()->set_index(index);
    piece.mutable_chunk()->set_payload(std::string(state.substr(at, kCheckpointChunkBytes)));
    open = writer->Write(piece);
  }
  if (open) writer->WritesDone();
  SEEP_RETURN_IF_ERROR(FromGrpcStatus("UploadCheckpoint", writer->Finish()));
  return static_cast<std::int64_t>(response.file_bytes());
}

core::Result<std::optional<FetchedCheckpoint>> RemoteLedger::NewestCheckpoint(
    const JobRecord& job, std::optional<std::uint64_t> below_step) {
  auto ctx = Context(timeout_ * kTransferTimeoutFactor);
  v1::DownloadCheckpointRequest request;
  SetLease(job.id, job.lease_epoch, request.mutable_lease());
  if (below_step) request.set_below_step(*below_step);
  auto reader = stub_->DownloadCheckpoint(ctx.get(), request);
  v1::DownloadCheckpointResponse message;
  std::optional<v1::CheckpointDownloadStart> start;
  std::string state;
  std::uint32_t expected_index = 0;
  core::Status broken;
  while (reader->Read(&message)) {
    if (message.has_start() && !start) {
      start = message.start();
    } else if (!start || !message.has_chunk() || message.chunk().index() != expected_index) {
      broken = core::DataLoss(
          fmt::format("WorkerService.DownloadCheckpoint: the stream broke its order at chunk {}",
                      expected_index));
      ctx->TryCancel();
    } else {
      state += message.chunk().payload();
      ++expected_index;
    }
  }
  SEEP_RETURN_IF_ERROR(FromGrpcStatus("DownloadCheckpoint", reader->Finish()));
  SEEP_RETURN_IF_ERROR(broken);
  if (!start) {
    return core::DataLoss("WorkerService.DownloadCheckpoint: the stream carried no start");
  }
  if (!start->found()) return std::optional<FetchedCheckpoint>();
  // Verified again here: what is restored is exactly what seepd verified and sent.
  if (state.size() != start->state_bytes() || Sha256(state) != start->state_sha256()) {
    return core::DataLoss(fmt::format(
        "WorkerService.DownloadCheckpoint: checkpoint {} arrived with {} of {} bytes or another "
        "SHA-256",
        start->name(), state.size(), start->state_bytes()));
  }
  FetchedCheckpoint fetched;
  fetched.step = start->step();
  fetched.name = start->name();
  fetched.meta.build_id = start->build_id();
  fetched.meta.job_id = job.id;
  fetched.meta.scene_sha256 = Sha256(job.scene);
  fetched.meta.step = start->header_step();
  fetched.meta.time_s = start->time_s();
  fetched.state = std::move(state);
  return std::optional<FetchedCheckpoint>(std::move(fetched));
}

core::Status RemoteLedger::StoreResultSeries(const std::string& id, std::int64_t epoch,
                                             const std::vector<std::string>& columns,
                                             const std::vector<double>& values,
                                             const std::string& state_sha256,
                                             const JobProgress& final_progress) {
  v1::StoreResultSeriesRequest request;
  SetLease(id, epoch, request.mutable_lease());
  request.mutable_columns()->Assign(columns.begin(), columns.end());
  request.mutable_values()->Assign(values.begin(), values.end());
  request.set_state_sha256(state_sha256);
  // With the series, not as a beat: a short job then never opens a KeepLease stream.
  ProgressToProto(final_progress, request.mutable_final_progress());
  v1::StoreResultSeriesResponse response;
  return FromGrpcStatus("StoreResultSeries",
                        stub_->StoreResultSeries(Context(timeout_).get(), request, &response));
}

core::Status RemoteLedger::Finish(const std::string& id, std::int64_t epoch, JobState state,
                                  const std::string& error_code, const std::string& error_message,
                                  const std::vector<std::pair<std::string, double>>& metrics,
                                  double wall_time_s) {
  CloseStream(id, epoch);
  v1::FinishJobRequest request;
  SetLease(id, epoch, request.mutable_lease());
  request.set_state(JobStateToProto(state));
  request.set_error_code(error_code);
  request.set_error_message(error_message);
  for (const auto& [name, value] : metrics) {
    v1::NamedValue* m = request.add_metrics();
    m->set_name(name);
    m->set_value(value);
  }
  request.set_wall_time_s(wall_time_s);
  v1::FinishJobResponse response;
  return FromGrpcStatus("FinishJob", stub_->FinishJob(Context(timeout_).get(), request, &response));
}

core::Status RemoteLedger::ReleaseLease(const std::string& id, std::int64_t epoch) {
  CloseStream(id, epoch);
  v1::ReturnJobRequest request;
  SetLease(id, epoch, request.mutable_lease());
  v1::ReturnJobResponse response;
  return FromGrpcStatus("ReturnJob", stub_->ReturnJob(Context(timeout_).get(), request, &response));
}

}  // namespace seep::service
