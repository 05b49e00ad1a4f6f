// SeepServiceImpl::DeleteJob and ListJobEvents: the housekeeping calls of a job service.
#include <fmt/format.h>

#include "codec/job_codec.h"
#include "jobs/checkpoint_removal.h"
#include "rpc/handler.h"
#include "rpc/page_token.h"
#include "rpc/seep_service.h"

namespace seep::service {

grpc::Status SeepServiceImpl::DeleteJob(grpc::ServerContext* ctx, const v1::DeleteJobRequest* req,
                                        v1::DeleteJobResponse* resp) {
  return Guarded(ctx, "DeleteJob", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    // The records go first, in one transaction; the files after. A crash in between leaves
    // files no record points to, which the next start's sweep removes.
    SEEP_ASSIGN_OR_RETURN(const std::vector<CheckpointRecord> records, store_.Delete(req->id()));
    const RemovedFiles removed = FinishDeletion({req->id()}, records);
    logger_->info("job {} deleted with {} checkpoint file(s), {} bytes", req->id(), removed.files,
                  removed.bytes);
    resp->set_id(req->id());
    resp->set_checkpoints_deleted(static_cast<std::uint32_t>(removed.files));
    resp->set_bytes_freed(removed.bytes);
    return core::Status::Ok();
  });
}

RemovedFiles SeepServiceImpl::FinishDeletion(const std::vector<std::string>& job_ids,
                                             const std::vector<CheckpointRecord>& records) {
  const RemovedFiles removed = RemoveCheckpointFiles(records, *logger_);
  for (const std::string& id : job_ids) hub_.Finished(id);
  return removed;
}

grpc::Status SeepServiceImpl::ListJobEvents(grpc::ServerContext* ctx,
                                            const v1::ListJobEventsRequest* req,
                                            v1::ListJobEventsResponse* resp) {
  return Guarded(ctx, "ListJobEvents", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    constexpr std::uint32_t kDefaultEvents = 200;
    const std::uint32_t limit = req->page_size() == 0 ? kDefaultEvents : PageSize(req->page_size());
    SEEP_ASSIGN_OR_RETURN(const std::optional<std::int64_t> after,
                          DecodePageToken(req->page_token(), *req, "ListJobEvents"));
    // One more than asked for tells whether another page follows.
    SEEP_ASSIGN_OR_RETURN(std::vector<JobEventRecord> events,
                          store_.ListEvents(req->id(), after.value_or(0), limit + 1));
    const bool more = events.size() > limit;
    if (more) events.resize(limit);
    resp->set_id(req->id());
    for (const JobEventRecord& event : events) JobEventToProto(event, resp->add_events());
    if (more) resp->set_next_page_token(EncodePageToken(events.back().id, *req));
    return core::Status::Ok();
  });
}

}  // namespace seep::service
