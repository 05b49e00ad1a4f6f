// SeepServiceImpl::GetJobFields: a simulation job's fields at one of its checkpoints.
//
// The one handler that needs physics: it rebuilds the job's network from its stored scene
// (deterministic, see simulation_snapshot.h), restores the chosen checkpoint's state
// (LoadNewestCheckpoint, as a resumed job does) and collects the arrays
// (core::CollectSceneFields, and the bonds and wall segments of dem_fields_codec.h). It does not
// step the simulation. The store is read on the handler thread; the physics runs on the
// PhysicsPool, with a job's thread budget, while the handler waits for it and gives up when the
// call is cancelled or passes its deadline.
#include <fmt/format.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "codec/dem_fields_codec.h"
#include "codec/fields_codec.h"
#include "codec/scene_codec.h"
#include "jobs/newest_checkpoint.h"
#include "rpc/handler.h"
#include "seep/core/run/scene_fields.h"
#include "seep/core/run/simulation.h"

namespace seep::service {
namespace {

// How often a waiting handler looks at its call: a cancelled call is noticed this late at most.
constexpr std::chrono::milliseconds kWaitSlice{50};

std::string JoinSteps(const std::vector<CheckpointRecord>& records) {
  std::string out;
  for (auto it = records.rbegin(); it != records.rend(); ++it) {
    if (!out.empty()) out += ", ";
    out += std::to_string(it->step);
  }
  return out;
}

// The physics of GetJobFields, on a pool thread: the job's scene, a simulation restored from the
// newest usable candidate (newest first), its fields. `records`: every checkpoint of the job.
grpc::Status RestoreAndCollect(const JobRecord& job, const std::vector<CheckpointRecord>& records,
                               const std::vector<CheckpointRecord>& candidates,
                               const std::shared_ptr<spdlog::logger>& logger,
                               v1::GetJobFieldsResponse* resp) {
  v1::Scene scene_pb;
  if (!scene_pb.ParseFromString(job.scene)) {
    return {grpc::StatusCode::DATA_LOSS, fmt::format("job {}: stored scene unreadable", job.id)};
  }
  auto spec = DecodeScene(scene_pb);  // validated by Simulation::Create
  if (!spec.ok()) return ToGrpcStatus(spec.status());
  auto sim = core::Simulation::Create(*spec, logger);
  if (!sim.ok()) return ToGrpcStatus(sim.status());
  // Every bond the run ever had, before the checkpoint's state replaces them (the DEM drops
  // broken bonds; dem_fields_codec.h).
  const BondList at_set_up = CurrentBonds(*sim);
  // Every candidate passed over is kept for the error.
  std::string skipped;
  const auto restored =
      LoadNewestCheckpoint(job, candidates, *sim, [&](const SkippedCheckpoint& s) {
        const core::Status why =
            s.foreign
                ? core::DataLoss(fmt::format(
                      "checkpoint at step {}: belongs to another job or scene", s.record.step))
                : s.why;
        skipped += fmt::format("{}step {}: {}", skipped.empty() ? "" : "; ", s.record.step,
                               why.ToString());
      });
  if (!restored) {
    return {grpc::StatusCode::DATA_LOSS,
            fmt::format("job {}: no usable checkpoint ({})", job.id, skipped)};
  }
  resp->set_job_id(job.id);
  resp->set_step(sim->step());
  resp->set_time_s(sim->time_s());
  for (auto it = records.rbegin(); it != records.rend(); ++it) resp->add_available_steps(it->step);
  SceneFieldsToProto(core::CollectSceneFields(*sim), resp->mutable_fields());
  DemFieldsToProto(*sim, at_set_up, resp->mutable_fields());
  return grpc::Status::OK;
}

// Runs `physics` on the pool and waits for it while the call lasts.
grpc::Status RunOnPool(PhysicsPool& pool, const grpc::ServerContext& ctx,
                       std::function<grpc::Status()> physics) {
  auto status = std::make_shared<grpc::Status>();
  auto ticket = pool.Post([status, physics = std::move(physics)] { *status = physics(); });
  if (!ticket) {
    return {grpc::StatusCode::RESOURCE_EXHAUSTED,
            "GetJobFields: too many field requests at once; try again shortly"};
  }
  while (!ticket->WaitFor(kWaitSlice)) {
    if (ctx.IsCancelled()) {  // the client went away or the deadline passed
      ticket->Abandon();
      return {grpc::StatusCode::CANCELLED, "GetJobFields: the call ended before its fields"};
    }
  }
  return *status;
}

}  // namespace

grpc::Status SeepServiceImpl::GetJobFields(grpc::ServerContext* ctx,
                                           const v1::GetJobFieldsRequest* req,
                                           v1::GetJobFieldsResponse* resp) {
  return Guarded(ctx, "GetJobFields", [&]() -> grpc::Status {
    if (core::Status s = RequireId(req->job_id(), "job_id"); !s.ok()) return ToGrpcStatus(s);
    auto job = store_.Get(req->job_id());
    if (!job.ok()) return ToGrpcStatus(job.status());
    if (job->kind != JobKind::kSimulation) {
      return {
          grpc::StatusCode::FAILED_PRECONDITION,
          fmt::format("job {} is a calibration job: only a simulation job has fields", job->id)};
    }
    auto records = store_.ListCheckpoints(job->id);  // newest first
    if (!records.ok()) return ToGrpcStatus(records.status());
    if (records->empty()) {
      return {grpc::StatusCode::FAILED_PRECONDITION,
              fmt::format("job {} ({}) has no checkpoint yet: fields exist once it has written "
                          "one (periodically while it runs, and at its end)",
                          job->id, JobStateName(job->state))};
    }
    std::vector<CheckpointRecord> candidates;
    for (const CheckpointRecord& r : *records) {
      if (req->step() == 0 || r.step == req->step()) candidates.push_back(r);
    }
    if (candidates.empty()) {
      return {grpc::StatusCode::INVALID_ARGUMENT,
              fmt::format("step: job {} has no checkpoint at step {}; available steps: {}", job->id,
                          req->step(), JoinSteps(*records))};
    }
    // The pool's task owns everything it reads: the handler may return before it ends.
    auto out = std::make_shared<v1::GetJobFieldsResponse>();
    grpc::Status status =
        RunOnPool(physics_, *ctx,
                  [job = std::move(*job), records = std::move(*records),
                   candidates = std::move(candidates), logger = logger_,
                   out] { return RestoreAndCollect(job, records, candidates, logger, out.get()); });
    if (!status.ok()) return status;
    // Bounded, so that no client is sent more than it can take (gRPC's own send limit would
    // only say RESOURCE_EXHAUSTED without the figures).
    if (const std::size_t bytes = out->ByteSizeLong(); bytes > guards_.max_response_bytes) {
      return {grpc::StatusCode::RESOURCE_EXHAUSTED,
              fmt::format("GetJobFields: the fields of job {} at step {} take {} bytes, over the "
                          "limit of {} bytes per response (seepd --max-response-bytes)",
                          out->job_id(), out->step(), bytes, guards_.max_response_bytes)};
    }
    resp->Swap(out.get());
    return status;
  });
}

}  // namespace seep::service
