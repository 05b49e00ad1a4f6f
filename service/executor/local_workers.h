// LocalWorkers: seepd's own workers as child processes (seepd --isolation process, the default).
// Each is a seep-worker that runs one job at a time through the WorkerService, dialing seepd on a
// socket in its data folder, so that a job that crashes, aborts or runs out of memory ends its
// own process and not seepd: the job is FAILED naming the signal (or exit status), the memory
// limit and the last lines its process logged, and a new process takes the slot.
//
// Each process is limited in address space (memory_limit_mb, RLIMIT_AS in seep-worker) and in
// threads (the runner flags' threads per job), and seepd watches its jobs once a second: a job
// that outlives the time limit by the grace (a set-up that never reaches a step, a step that
// never ends) or whose cancel its process has not acted on within the grace has its process
// killed, and is FAILED (DEADLINE_EXCEEDED) or CANCELLED. Its other jobs (a finished run whose
// end was being recorded) keep their leases until they run out, and are queued again by the
// rescuer. The processes die with seepd (PR_SET_PDEATHSIG); one that dies by itself is restarted
// after a pause that doubles, up to 30 s, while processes keep dying within seconds of starting.
#pragma once

#include <spdlog/logger.h>
#include <sys/types.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "jobs/job_hub.h"
#include "jobs/runner_flags.h"
#include "seep/core/status.h"
#include "store/job_store.h"

namespace seep::service {

struct LocalWorkersOptions {
  std::string worker_path;  // the seep-worker binary
  std::string server;       // the address the processes dial (e.g. unix:<data-dir>/worker.sock)
  int count = 1;            // processes, each running one job at a time
  RunnerFlags runner;       // threads per job, lease, checkpoint cadence, log level
  std::string token;        // seepd's bearer token (in the processes' environment); empty: none
  std::uint64_t memory_limit_mb = 0;  // address space of each process; 0: none
  double job_time_limit_s = 0.0;      // wall time of one claim, set-up included; 0: none
  // How long a process may take to act on a cancel, or run past the time limit, before seepd
  // ends it.
  std::chrono::milliseconds grace{5000};
  std::vector<std::string> extra_args;  // passed on as they are (test hooks)
};

class LocalWorkers {
 public:
  LocalWorkers(JobStore& store, JobHub& hub, LocalWorkersOptions options,
               std::shared_ptr<spdlog::logger> logger);
  ~LocalWorkers();
  LocalWorkers(const LocalWorkers&) = delete;
  LocalWorkers& operator=(const LocalWorkers&) = delete;

  // FAILED_PRECONDITION when the worker binary is missing; else starts the processes.
  core::Status Start();
  // Jobs were queued: every idle process looks for one now (SIGUSR1) rather than at its next
  // poll.
  void Wake();
  // SIGTERM to every process (running jobs stop at a step, are checkpointed and given back), then
  // SIGKILL to those still alive after `timeout`; returns once all have ended.
  void Stop(std::chrono::milliseconds timeout);
  // How many processes are alive now (for tests and the start-up log).
  int alive() const;

 private:
  struct Slot;
  // Why seepd ended a process itself.
  enum class KillReason { kNone, kCancel, kTimeLimit };
  struct Death {
    int wait_status = 0;
    KillReason reason = KillReason::kNone;
    std::string reason_job;  // the job the kill was for
    std::deque<std::string> last_lines;
    std::map<std::string, std::int64_t> cancel_seen;  // job id -> when a cancel was first seen
    std::chrono::steady_clock::time_point started;
  };

  void Supervise(Slot& slot);
  // Starts one process for the slot; its pid and the read end of its output.
  core::Status Spawn(Slot& slot, int& output_fd);
  // Forwards the process's output to the log until it ends; ends it for a stale cancel, the time
  // limit, or the shutdown's deadline.
  Death Watch(Slot& slot, int output_fd);
  // Every second: the jobs the process holds, against the time limit and pending cancels.
  void CheckHeldJobs(Slot& slot, Death& death);
  // Records what the death of a process means for the job it was running.
  void Bury(const Slot& slot, pid_t pid, const Death& death);

  JobStore& store_;
  JobHub& hub_;
  LocalWorkersOptions options_;
  std::shared_ptr<spdlog::logger> logger_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::atomic<bool> stopping_{false};
  std::atomic<std::int64_t> kill_at_ms_{0};  // the shutdown's deadline (steady ms); 0: none
};

// "local-<index>-<pid>-": how the leases of one worker process begin (seep-worker names its
// leases <name>-<pid>-<random>).
std::string LocalWorkerLeasePrefix(const std::string& name, pid_t pid);

// The address seepd's worker processes dial: a socket in the data folder, or (when its path is
// too long for a socket's name) one in the abstract namespace named after this process.
std::string LocalWorkerSocketAddress(const std::filesystem::path& data_dir, std::uint64_t nonce);

// The default address space of one worker process: the machine's memory, less a tenth for
// seepd and the system, shared out among the workers; at least 1 GiB. 0 (none) in a build
// with AddressSanitizer, whose shadow memory takes terabytes of address space.
std::uint64_t DefaultJobMemoryLimitMb(int workers);

// "was killed by signal 11 (SIGSEGV, Segmentation fault)" or "exited with status 3".
std::string DescribeWaitStatus(int wait_status);

}  // namespace seep::service
