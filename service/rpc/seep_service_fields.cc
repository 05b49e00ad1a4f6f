// SeepServiceImpl::GetJobFields: a simulation job's fields at one of its checkpoints.
//
// The one handler that runs physics code: it rebuilds the job's network from its stored scene
// (deterministic, see simulation_snapshot.h), restores the chosen checkpoint's state and collects
// the arrays (core::CollectSceneFields). It does not step the simulation.
#include <fmt/format.h>

#include <exception>
#include <string>
#include <vector>

#include "codec/fields_codec.h"
#include "codec/scene_codec.h"
#include "codec/simulation_state_codec.h"
#include "rpc/seep_service.h"
#include "rpc/status_mapping.h"
#include "seep/core/run/scene_fields.h"
#include "seep/core/run/simulation.h"
#include "store/checkpoint_io.h"

namespace seep::service {
namespace {

std::string JoinSteps(const std::vector<CheckpointRecord>& records) {
  std::string out;
  for (auto it = records.rbegin(); it != records.rend(); ++it) {
    if (!out.empty()) out += ", ";
    out += std::to_string(it->step);
  }
  return out;
}

// The checkpoint's state, checked to belong to this job and scene.
core::Result<core::SimulationSnapshot> LoadSnapshot(const JobRecord& job,
                                                    const CheckpointRecord& record) {
  SEEP_ASSIGN_OR_RETURN(CheckpointFile file, ReadCheckpointFile(record.path));
  if (file.meta.job_id != job.id || file.meta.scene_sha256 != Sha256(job.scene)) {
    return core::DataLoss(
        fmt::format("checkpoint at step {}: belongs to another job or scene", record.step));
  }
  return ParseSimulationState(file.state);
}

grpc::Status CollectJobFields(JobStore& store, const std::shared_ptr<spdlog::logger>& logger,
                              const v1::GetJobFieldsRequest& req, v1::GetJobFieldsResponse* resp) {
  if (req.job_id().empty()) return {grpc::StatusCode::INVALID_ARGUMENT, "job_id: is required"};
  auto job = store.Get(req.job_id());
  if (!job.ok()) return ToGrpcStatus(job.status());
  if (job->kind != JobKind::kSimulation) {
    return {grpc::StatusCode::FAILED_PRECONDITION,
            fmt::format("job {} is a calibration job: only a simulation job has fields", job->id)};
  }
  auto records = store.ListCheckpoints(job->id);  // newest first
  if (!records.ok()) return ToGrpcStatus(records.status());
  if (records->empty()) {
    return {grpc::StatusCode::FAILED_PRECONDITION,
            fmt::format("job {} ({}) has no checkpoint yet: fields exist once it has written one "
                        "(periodically while it runs, and at its end)",
                        job->id, JobStateName(job->state))};
  }
  std::vector<const CheckpointRecord*> candidates;
  if (req.step() == 0) {
    for (const CheckpointRecord& r : *records) candidates.push_back(&r);
  } else {
    for (const CheckpointRecord& r : *records) {
      if (r.step == req.step()) candidates.push_back(&r);
    }
    if (candidates.empty()) {
      return {grpc::StatusCode::INVALID_ARGUMENT,
              fmt::format("step: job {} has no checkpoint at step {}; available steps: {}", job->id,
                          req.step(), JoinSteps(*records))};
    }
  }
  v1::Scene scene_pb;
  if (!scene_pb.ParseFromString(job->scene)) {
    return {grpc::StatusCode::DATA_LOSS, fmt::format("job {}: stored scene unreadable", job->id)};
  }
  auto spec = SceneFromProto(scene_pb);
  if (!spec.ok()) return ToGrpcStatus(spec.status());
  auto sim = core::Simulation::Create(*spec, logger);
  if (!sim.ok()) return ToGrpcStatus(sim.status());
  // The newest checkpoint that reads, verifies and restores; every failure is kept for the error.
  std::string skipped;
  for (const CheckpointRecord* record : candidates) {
    auto snapshot = LoadSnapshot(*job, *record);
    core::Status restored = snapshot.ok() ? sim->Restore(*snapshot) : snapshot.status();
    if (!restored.ok()) {
      skipped += fmt::format("{}step {}: {}", skipped.empty() ? "" : "; ", record->step,
                             restored.ToString());
      continue;
    }
    resp->set_job_id(job->id);
    resp->set_step(sim->step());
    resp->set_time_s(sim->time_s());
    for (auto it = records->rbegin(); it != records->rend(); ++it) {
      resp->add_available_steps(it->step);
    }
    SceneFieldsToProto(core::CollectSceneFields(*sim), resp->mutable_fields());
    return grpc::Status::OK;
  }
  return {grpc::StatusCode::DATA_LOSS,
          fmt::format("job {}: no usable checkpoint ({})", job->id, skipped)};
}

}  // namespace

grpc::Status SeepServiceImpl::GetJobFields(grpc::ServerContext* ctx,
                                           const v1::GetJobFieldsRequest* req,
                                           v1::GetJobFieldsResponse* resp) {
  if (guards_.auth != nullptr) {
    if (grpc::Status denied = guards_.auth->Check(*ctx); !denied.ok()) return denied;
  }
  try {
    return CollectJobFields(store_, logger_, *req, resp);
  } catch (const std::exception& e) {
    logger_->error("GetJobFields: unexpected exception: {}", e.what());
    return {grpc::StatusCode::INTERNAL, "GetJobFields: internal error"};
  }
}

}  // namespace seep::service
