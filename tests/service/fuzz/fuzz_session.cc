#include "fuzz_session.h"

#include <fmt/format.h>
#include <grpcpp/impl/client_unary_call.h>

#include <cmath>
#include <thread>

#include "refusal_rule.h"
#include "rpc/status_mapping.h"

namespace seep::fuzz {
namespace {

constexpr std::size_t kMaxKeptViolations = 200;

bool Terminal(v1::JobState state) {
  return state == v1::JOB_STATE_SUCCEEDED || state == v1::JOB_STATE_FAILED ||
         state == v1::JOB_STATE_CANCELLED;
}

bool Mutating(const std::string& method) {
  return method == "SubmitJob" || method == "SubmitSweep" || method == "DeleteJob" ||
         method == "DeleteSweep";
}

// A failure reason's first words, for the tally: what kind of failure, not which job.
std::string ReasonKind(const v1::JobError& error) {
  std::string text = error.code() + ": " + error.message();
  if (text.size() > 70) text = text.substr(0, 70) + "...";
  for (char& c : text) {
    if (c >= '0' && c <= '9') c = '#';
  }
  return text;
}

template <typename Message>
bool Parse(const grpc::ByteBuffer& buffer, Message* message) {
  std::vector<grpc::Slice> slices;
  if (!buffer.Dump(&slices).ok()) return false;
  std::string bytes;
  for (const grpc::Slice& s : slices)
    bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  return message->ParseFromString(bytes);
}

}  // namespace

FuzzSession::FuzzSession(std::shared_ptr<grpc::Channel> channel, pid_t seepd_pid,
                         std::filesystem::path data_dir, FuzzOptions options)
    : channel_(std::move(channel)),
      stub_(v1::SeepService::NewStub(channel_)),
      observer_(seepd_pid, std::move(data_dir)),
      options_(options) {
  expected_jobs_ = std::max<std::int64_t>(0, observer_.CountRows("jobs"));
  expected_sweeps_ = std::max<std::int64_t>(0, observer_.CountRows("sweeps"));
}

void FuzzSession::Violation(std::uint64_t index, const FuzzRequest* request,
                            const std::string& problem) {
  if (violations_.size() >= kMaxKeptViolations) return;
  std::string line = fmt::format("seed {} request {}", options_.seed, index);
  if (request != nullptr) line += fmt::format(" ({})", request->method);
  line += ": " + problem;
  if (request != nullptr) {
    std::string what = request->what;
    if (what.size() > 600) what = what.substr(0, 600) + "...";
    line += "\n    request: " + what;
  }
  violations_.push_back(std::move(line));
}

grpc::Status FuzzSession::Call(const FuzzRequest& request, grpc::ByteBuffer* response) {
  grpc::Slice slice(request.bytes);
  grpc::ByteBuffer buffer(&slice, 1);
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + options_.call_deadline);
  const std::string path = "/seep.v1.SeepService/" + request.method;
  const grpc::internal::RpcMethod method(path.c_str(), grpc::internal::RpcMethod::NORMAL_RPC);
  return grpc::internal::BlockingUnaryCall<grpc::ByteBuffer, grpc::ByteBuffer>(
      channel_.get(), method, &ctx, buffer, response);
}

grpc::Status FuzzSession::Watch(const FuzzRequest& request) {
  // A short look: the stream ends by itself for a finished job, else at the deadline.
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(200));
  const auto& watch = static_cast<const v1::WatchJobRequest&>(*request.message);
  auto reader = stub_->WatchJob(&ctx, watch);
  v1::JobEvent event;
  while (reader->Read(&event)) {
  }
  grpc::Status status = reader->Finish();
  if (status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED) return grpc::Status::OK;
  return status;
}

void FuzzSession::Track(std::uint64_t index, const FuzzRequest& request, const v1::Job& job) {
  if (jobs_.count(job.id()) != 0) return;
  jobs_[job.id()] = TrackedJob{index, request.what, false};
  ++counts_.jobs_accepted;
  if (job.has_scene() && job.scene().stages_size() > 0) staged_[job.id()] = job.scene();
}

void FuzzSession::Forget(const std::string& id) {
  if (jobs_.erase(id) != 0) ++counts_.jobs_deleted;
  staged_.erase(id);
}

void FuzzSession::RebuildContext() {
  context_.job_ids.clear();
  for (const auto& [id, job] : jobs_) context_.job_ids.push_back(id);
  context_.sweep_ids.clear();
  for (const auto& [id, members] : sweeps_) context_.sweep_ids.push_back(id);
  context_.staged_jobs.assign(staged_.begin(), staged_.end());
  context_.request_ids.assign(request_ids_.begin(), request_ids_.end());
}

// What an accepted call changed: the jobs and sweeps it made, cancelled or deleted.
void FuzzSession::Absorb(std::uint64_t index, const FuzzRequest& request,
                         const grpc::ByteBuffer& response) {
  const std::string& m = request.method;
  const auto parse_failed = [&] {
    Violation(index, &request, "OK, but the response does not parse");
  };
  if (m == "SubmitJob") {
    v1::SubmitJobResponse r;
    if (!Parse(response, &r)) return parse_failed();
    if (r.created()) {
      ++expected_jobs_;
      Track(index, request, r.job());
    }
    if (!r.job().request_id().empty()) request_ids_.insert(r.job().request_id());
  } else if (m == "SubmitSweep") {
    v1::SubmitSweepResponse r;
    if (!Parse(response, &r)) return parse_failed();
    if (r.created()) {
      ++expected_sweeps_;
      expected_jobs_ += r.sweep().jobs_size();
      std::vector<std::string>& members = sweeps_[r.sweep().id()];
      for (const v1::SweepJob& job : r.sweep().jobs()) {
        Track(index, request, job.job());
        members.push_back(job.job().id());
      }
    }
    if (!r.sweep().request_id().empty()) request_ids_.insert(r.sweep().request_id());
  } else if (m == "DeleteJob") {
    v1::DeleteJobResponse r;
    if (!Parse(response, &r)) return parse_failed();
    --expected_jobs_;
    Forget(r.id());
  } else if (m == "DeleteSweep") {
    v1::DeleteSweepResponse r;
    if (!Parse(response, &r)) return parse_failed();
    --expected_sweeps_;
    expected_jobs_ -= r.jobs_deleted();
    for (const std::string& id : sweeps_[r.id()]) Forget(id);
    sweeps_.erase(r.id());
  } else if (m == "CancelJob") {
    v1::CancelJobResponse r;
    if (!Parse(response, &r)) return parse_failed();
    if (auto it = jobs_.find(r.job().id()); it != jobs_.end()) it->second.cancel_requested = true;
  } else if (m == "CancelSweep") {
    v1::CancelSweepResponse r;
    if (!Parse(response, &r)) return parse_failed();
    for (const std::string& id : sweeps_[r.sweep().id()]) {
      if (auto it = jobs_.find(id); it != jobs_.end()) it->second.cancel_requested = true;
    }
  } else if (!request.streaming) {
    // Every other answer must at least be the method's response message.
    std::unique_ptr<google::protobuf::Message> message(
        google::protobuf::MessageFactory::generated_factory()
            ->GetPrototype(SeepMethod(m).output_type())
            ->New());
    if (!Parse(response, message.get())) parse_failed();
  }
}

void FuzzSession::CheckStore(std::uint64_t index, const FuzzRequest& request) {
  const std::int64_t jobs = observer_.CountRows("jobs");
  const std::int64_t sweeps = observer_.CountRows("sweeps");
  if (jobs != expected_jobs_ || sweeps != expected_sweeps_) {
    Violation(
        index, &request,
        fmt::format("the store holds {} jobs and {} sweeps; the answers so far made {} and {}",
                    jobs, sweeps, expected_jobs_, expected_sweeps_));
    // Counted from here on, so that one difference is reported once.
    expected_jobs_ = jobs;
    expected_sweeps_ = sweeps;
  }
}

void FuzzSession::CheckProcess(std::uint64_t index, const FuzzRequest& request) {
  if (!observer_.Alive()) {
    Violation(index, &request, fmt::format("seepd (pid {}) is gone", observer_.pid()));
    seepd_gone_ = true;
    return;
  }
  const std::size_t rss = observer_.RssBytes();
  counts_.peak_rss_bytes = std::max(counts_.peak_rss_bytes, rss);
  if (options_.rss_limit_bytes > 0 && rss > options_.rss_limit_bytes && !rss_reported_) {
    Violation(index, &request,
              fmt::format("seepd's RSS is {} MiB, over the bound of {} MiB", rss >> 20,
                          options_.rss_limit_bytes >> 20));
    rss_reported_ = true;
  }
}

void FuzzSession::WaitForBacklog(std::uint64_t index) {
  std::int64_t backlog = observer_.CountUnfinished();
  if (options_.max_backlog <= 0 || backlog <= options_.max_backlog) return;
  const auto start = std::chrono::steady_clock::now();
  auto progress = start;
  while (backlog > options_.max_backlog / 2 && observer_.Alive()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const std::int64_t now = observer_.CountUnfinished();
    if (now < backlog) progress = std::chrono::steady_clock::now();
    backlog = now;
    if (std::chrono::steady_clock::now() - progress > options_.stall) {
      Violation(index, nullptr,
                fmt::format("{} jobs QUEUED or RUNNING, and none ended for {} s", backlog,
                            options_.stall.count()));
      // The run stops here: every request after it would wait as long again.
      queue_stuck_ = true;
      break;
    }
  }
  counts_.backlog_wait_s +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void FuzzSession::SendRequests() {
  const auto start = std::chrono::steady_clock::now();
  for (std::uint64_t i = 0; i < options_.requests && !seepd_gone_; ++i) {
    WaitForBacklog(i);
    if (queue_stuck_) break;
    RebuildContext();
    FuzzRandom random(RequestSeed(options_.seed, i));
    const FuzzRequest request = GenerateRequest(random, context_, options_.limits);
    counts_.redrawn += static_cast<std::uint64_t>(request.redrawn);
    grpc::ByteBuffer response;
    const grpc::Status status = request.streaming ? Watch(request) : Call(request, &response);
    ++counts_.requests;
    ++counts_.by_method[request.method];
    ++counts_.by_code[service::GrpcCodeName(status.error_code())];
    if (status.ok()) {
      Absorb(i, request, response);
    } else if (const std::string problem =
                   RefusalProblem(*request.type, request.method, request.id, status);
               !problem.empty()) {
      std::string message = status.error_message();
      if (message.size() > 300) message = message.substr(0, 300) + "...";
      Violation(i, &request,
                fmt::format("{} \"{}\": {}", service::GrpcCodeName(status.error_code()), message,
                            problem));
    }
    CheckProcess(i, request);
    if (Mutating(request.method) && !seepd_gone_) CheckStore(i, request);
    if (options_.progress != nullptr && (i + 1) % options_.progress_every == 0) {
      *options_.progress << fmt::format("{} requests, {} jobs accepted, {} violations\n", i + 1,
                                        counts_.jobs_accepted, violations_.size())
                         << std::flush;
    }
  }
  counts_.seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<v1::Job> FuzzSession::ListAll() {
  std::vector<v1::Job> all;
  std::string token;
  do {
    grpc::ClientContext ctx;
    ctx.set_deadline(std::chrono::system_clock::now() + options_.call_deadline);
    v1::ListJobsRequest request;
    request.set_page_size(1000);
    request.set_page_token(token);
    v1::ListJobsResponse response;
    const grpc::Status status = stub_->ListJobs(&ctx, request, &response);
    if (!status.ok()) {
      Violation(counts_.requests, nullptr, "ListJobs at the end: " + status.error_message());
      return all;
    }
    all.insert(all.end(), response.jobs().begin(), response.jobs().end());
    token = response.next_page_token();
  } while (!token.empty());
  return all;
}

void FuzzSession::CheckEndings() {
  const auto start = std::chrono::steady_clock::now();
  const std::uint64_t at = counts_.requests;
  if (seepd_gone_) return;
  std::map<std::string, v1::Job> seen;
  const auto deadline = start + options_.end_wait;
  for (;;) {
    seen.clear();
    for (v1::Job& job : ListAll()) seen[job.id()] = std::move(job);
    bool all_ended = true;
    for (const auto& [id, tracked] : jobs_) {
      const auto it = seen.find(id);
      all_ended = all_ended && it != seen.end() && Terminal(it->second.state());
    }
    if (all_ended || std::chrono::steady_clock::now() > deadline || !observer_.Alive()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  if (static_cast<std::int64_t>(seen.size()) != expected_jobs_) {
    Violation(
        at, nullptr,
        fmt::format("ListJobs lists {} jobs; the answers made {}", seen.size(), expected_jobs_));
  }
  for (const auto& [id, tracked] : jobs_) {
    const auto it = seen.find(id);
    const std::string who = fmt::format("job {} (made by request {}: {})", id, tracked.request,
                                        tracked.what.substr(0, 400));
    if (it == seen.end()) {
      Violation(at, nullptr, who + " is not listed, and the fuzzer did not delete it");
      continue;
    }
    const v1::Job& job = it->second;
    switch (job.state()) {
      case v1::JOB_STATE_SUCCEEDED: {
        ++counts_.succeeded;
        grpc::ClientContext ctx;
        ctx.set_deadline(std::chrono::system_clock::now() + options_.call_deadline);
        v1::GetResultRequest request;
        request.set_id(id);
        v1::GetResultResponse result;
        const grpc::Status status = stub_->GetResult(&ctx, request, &result);
        if (!status.ok()) {
          Violation(at, nullptr, who + " SUCCEEDED, but GetResult: " + status.error_message());
          break;
        }
        for (const auto& [name, value] : result.result().metrics()) {
          if (!std::isfinite(value)) {
            Violation(at, nullptr,
                      fmt::format("{} SUCCEEDED with metric {} = {}", who, name, value));
          }
        }
        break;
      }
      case v1::JOB_STATE_FAILED:
        ++counts_.failed;
        ++counts_.failure_reasons[ReasonKind(job.error())];
        if (job.error().code() == "DEADLINE_EXCEEDED") ++counts_.failed_at_time_limit;
        if (job.error().message().empty()) Violation(at, nullptr, who + " FAILED without a reason");
        break;
      case v1::JOB_STATE_CANCELLED:
        ++counts_.cancelled;
        if (!tracked.cancel_requested) {
          Violation(at, nullptr, who + " was CANCELLED, but the fuzzer never cancelled it");
        }
        break;
      default:
        ++counts_.unfinished;
        Violation(at, nullptr,
                  fmt::format("{} is still {} {:.0f} s after the last request (step {})", who,
                              v1::JobState_Name(job.state()), options_.end_wait.count() * 1.0,
                              job.progress().step()));
        break;
    }
  }
  if (!observer_.Alive()) {
    Violation(at, nullptr, fmt::format("seepd (pid {}) is gone", observer_.pid()));
    return;
  }
  for (const std::string& orphan : observer_.CheckpointFoldersWithoutAJob()) {
    Violation(at, nullptr, "checkpoints/" + orphan + " belongs to no job of the store");
  }
  counts_.peak_rss_bytes = std::max(counts_.peak_rss_bytes, observer_.RssBytes());
  counts_.seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string FuzzSession::Report() const {
  std::string out = fmt::format(
      "fuzz seed {}: {} requests in {:.1f} s ({:.1f} s of it waiting for at most {} queued jobs)\n",
      options_.seed, counts_.requests, counts_.seconds, counts_.backlog_wait_s,
      options_.max_backlog);
  if (options_.limits.max_disks > 0 || options_.limits.max_sweep_jobs > 0) {
    out += fmt::format(
        "  left out: {} requests for scenes of {} to 20,000,000 disks (valid, but their set-up "
        "runs outside the job time limit: issue 50 item 2) or sweeps of {} to 10,000 jobs\n",
        counts_.redrawn, options_.limits.max_disks + 1, options_.limits.max_sweep_jobs + 1);
  }
  out += "  by method:";
  for (const auto& [method, n] : counts_.by_method) out += fmt::format(" {} {}", method, n);
  out += "\n  by code:";
  for (const auto& [code, n] : counts_.by_code) out += fmt::format(" {} {}", code, n);
  out += fmt::format(
      "\n  jobs: {} accepted, {} deleted by the fuzzer; {} SUCCEEDED, {} FAILED ({} at the time "
      "limit), {} CANCELLED, {} unfinished\n",
      counts_.jobs_accepted, counts_.jobs_deleted, counts_.succeeded, counts_.failed,
      counts_.failed_at_time_limit, counts_.cancelled, counts_.unfinished);
  for (const auto& [reason, n] : counts_.failure_reasons) {
    out += fmt::format("    FAILED {:>5} x {}\n", n, reason);
  }
  out += fmt::format("  seepd: pid {} {}, peak RSS {} MiB{}\n", observer_.pid(),
                     seepd_gone_ ? "GONE" : "alive", counts_.peak_rss_bytes >> 20,
                     options_.rss_limit_bytes > 0
                         ? fmt::format(" (bound {} MiB)", options_.rss_limit_bytes >> 20)
                         : std::string(" (not bounded here)"));
  out += fmt::format("  invariants: {}\n",
                     violations_.empty() ? std::string("all held")
                                         : fmt::format("{} violation(s)", violations_.size()));
  for (const std::string& v : violations_) out += "  - " + v + "\n";
  return out;
}

}  // namespace seep::fuzz
