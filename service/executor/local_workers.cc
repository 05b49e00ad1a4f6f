#include "executor/local_workers.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <map>

#include "jobs/wall_clock.h"

extern char** environ;

namespace seep::service {
namespace {

// Lines of a process's output kept for the message of a job it dies running, and the most kept
// of one line (a runaway line cannot fill a job's error).
constexpr std::size_t kLastLines = 8;
constexpr std::size_t kLineBytes = 400;
// A process that dies sooner than this after its start counts towards the restart pause.
constexpr auto kShortLife = std::chrono::seconds(10);
constexpr auto kLongestPause = std::chrono::seconds(30);
constexpr auto kPoll = std::chrono::milliseconds(100);
constexpr auto kJobCheck = std::chrono::milliseconds(1000);

std::int64_t SteadyMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Printable: a job's error and seepd's log get no control characters from a process's output.
std::string Printable(std::string_view line) {
  std::string out;
  for (const char c : line.substr(0, kLineBytes)) {
    out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  }
  if (line.size() > kLineBytes) out += "...";
  return out;
}

std::string Join(const std::deque<std::string>& lines) {
  std::string out;
  for (const std::string& line : lines) {
    if (!out.empty()) out += " | ";
    out += line;
  }
  return out;
}

}  // namespace

std::string LocalWorkerLeasePrefix(const std::string& name, pid_t pid) {
  return fmt::format("{}-{}-", name, pid);
}

std::string LocalWorkerSocketAddress(const std::filesystem::path& data_dir, std::uint64_t nonce) {
  std::error_code ec;
  const std::filesystem::path socket = std::filesystem::absolute(data_dir, ec) / "worker.sock";
  // sockaddr_un holds 108 bytes, its terminating zero included.
  if (!ec && socket.native().size() < 100) return "unix:" + socket.string();
  return fmt::format("unix-abstract:seepd-workers-{}-{:016x}", getpid(), nonce);
}

std::uint64_t DefaultJobMemoryLimitMb(int workers) {
#if defined(__SANITIZE_ADDRESS__)
  (void)workers;
  return 0;
#else
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page_bytes = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page_bytes <= 0) return 0;
  const std::uint64_t machine_mb =
      static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page_bytes) >> 20;
  return std::max<std::uint64_t>(1024, machine_mb * 9 / 10 / std::max(1, workers));
#endif
}

std::string DescribeWaitStatus(int wait_status) {
  if (WIFSIGNALED(wait_status)) {
    const int signal = WTERMSIG(wait_status);
    const char* abbreviation = sigabbrev_np(signal);
    const char* description = sigdescr_np(signal);
    return fmt::format("was killed by signal {} (SIG{}, {}){}", signal,
                       abbreviation != nullptr ? abbreviation : "?",
                       description != nullptr ? description : "unknown signal",
                       WCOREDUMP(wait_status) ? ", core dumped" : "");
  }
  if (WIFEXITED(wait_status)) return fmt::format("exited with status {}", WEXITSTATUS(wait_status));
  return fmt::format("ended (wait status {:#x})", wait_status);
}

struct LocalWorkers::Slot {
  int index = 0;
  std::string name;  // local-<index>
  mutable std::mutex mutex;
  pid_t pid =
      0;  // the live process; 0 between processes (mutex: a signal never reaches a reaped pid)
  std::jthread thread;
};

LocalWorkers::LocalWorkers(JobStore& store, JobHub& hub, LocalWorkersOptions options,
                           std::shared_ptr<spdlog::logger> logger)
    : store_(store), hub_(hub), options_(std::move(options)), logger_(std::move(logger)) {}

LocalWorkers::~LocalWorkers() { Stop(std::chrono::milliseconds(0)); }

core::Status LocalWorkers::Start() {
  if (access(options_.worker_path.c_str(), X_OK) != 0) {
    return core::FailedPrecondition(fmt::format(
        "seepd runs its jobs in seep-worker processes (--isolation process), but {} is not an "
        "executable file ({}); see --seep-worker",
        options_.worker_path, std::strerror(errno)));
  }
  for (int i = 1; i <= options_.count; ++i) {
    auto slot = std::make_unique<Slot>();
    slot->index = i;
    slot->name = fmt::format("local-{}", i);
    slots_.push_back(std::move(slot));
  }
  // Each slot's process is started by its own thread, and must be: PR_SET_PDEATHSIG fires when
  // the thread that forked ends, and this one lives as long as its slot.
  for (auto& slot : slots_) {
    slot->thread = std::jthread([this, s = slot.get()] { Supervise(*s); });
  }
  return core::Status::Ok();
}

void LocalWorkers::Wake() {
  for (const auto& slot : slots_) {
    std::lock_guard lock(slot->mutex);
    if (slot->pid > 0) kill(slot->pid, SIGUSR1);
  }
}

void LocalWorkers::Stop(std::chrono::milliseconds timeout) {
  if (stopping_.exchange(true)) {
    for (auto& slot : slots_) {
      if (slot->thread.joinable()) slot->thread.join();
    }
    return;
  }
  // Each slot's thread sends its process SIGTERM (one only: a second makes seep-worker exit at
  // once), a process it started a moment ago included.
  kill_at_ms_ = SteadyMs() + std::max<std::int64_t>(1, timeout.count());
  for (auto& slot : slots_) {
    if (slot->thread.joinable()) slot->thread.join();
  }
}

int LocalWorkers::alive() const {
  int count = 0;
  for (const auto& slot : slots_) {
    std::lock_guard lock(slot->mutex);
    count += slot->pid > 0 ? 1 : 0;
  }
  return count;
}

void LocalWorkers::Supervise(Slot& slot) {
  std::chrono::milliseconds pause{0};
  while (!stopping_) {
    int output_fd = -1;
    if (auto spawned = Spawn(slot, output_fd); !spawned.ok()) {
      logger_->error("worker {}: {}", slot.name, spawned.message());
      pause = std::clamp(pause * 2, std::chrono::milliseconds(500),
                         std::chrono::milliseconds(kLongestPause));
    } else {
      const pid_t pid = slot.pid;
      const Death death = Watch(slot, output_fd);
      if (stopping_) {
        if (!(WIFEXITED(death.wait_status) && WEXITSTATUS(death.wait_status) == 0)) {
          logger_->warn("worker {} (pid {}) {} while seepd stopped", slot.name, pid,
                        DescribeWaitStatus(death.wait_status));
        }
        break;
      }
      Bury(slot, pid, death);
      const bool short_life = std::chrono::steady_clock::now() - death.started < kShortLife;
      pause = short_life ? std::clamp(pause * 2, std::chrono::milliseconds(100),
                                      std::chrono::milliseconds(kLongestPause))
                         : std::chrono::milliseconds(0);
    }
    const auto until = std::chrono::steady_clock::now() + pause;
    while (!stopping_ && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(kPoll);
    }
  }
}

core::Status LocalWorkers::Spawn(Slot& slot, int& output_fd) {
  std::vector<std::string> args = {
      options_.worker_path, "--server", options_.server, "--workers", "1", "--name", slot.name,
      "--supervised"};
  const std::vector<std::string> runner = RunnerFlagArgs(options_.runner);
  args.insert(args.end(), runner.begin(), runner.end());
  args.insert(args.end(), {"--job-time-limit-s", fmt::format("{}", options_.job_time_limit_s),
                           "--memory-limit-mb", std::to_string(options_.memory_limit_mb)});
  args.insert(args.end(), options_.extra_args.begin(), options_.extra_args.end());
  // This process's environment, with the token (not in argv, which ps shows) and fewer malloc
  // arenas under a memory limit (each reserves 64 MiB of address space, and a limit of address
  // space counts reservations).
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string_view entry(*e);
    if (entry.starts_with("SEEP_TOKEN=") || entry.starts_with("SEEP_SERVER=") ||
        entry.starts_with("MALLOC_ARENA_MAX=")) {
      continue;
    }
    env.emplace_back(entry);
  }
  if (!options_.token.empty()) env.push_back("SEEP_TOKEN=" + options_.token);
  if (options_.memory_limit_mb > 0) env.emplace_back("MALLOC_ARENA_MAX=2");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<char*> envp;
  for (std::string& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);

  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    return core::Unavailable(fmt::format("no pipe for a worker process: {}", std::strerror(errno)));
  }
  const pid_t parent = getpid();
  std::lock_guard lock(slot.mutex);
  const pid_t pid = fork();
  if (pid < 0) {
    const int error = errno;
    close(fds[0]);
    close(fds[1]);
    return core::Unavailable(fmt::format("fork failed: {}", std::strerror(error)));
  }
  if (pid == 0) {
    // The child: async-signal-safe calls only until exec.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // seepd died before the line above
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0) dup2(null_fd, STDIN_FILENO);
    dup2(fds[1], STDOUT_FILENO);
    dup2(fds[1], STDERR_FILENO);
    close_range(3, ~0U, 0);
    struct sigaction default_action {};
    default_action.sa_handler = SIG_DFL;
    sigaction(SIGPIPE, &default_action, nullptr);
    // Every signal open (seepd's threads block its stop signals) but SIGUSR1, which the worker
    // opens once it handles it.
    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGUSR1);
    sigprocmask(SIG_SETMASK, &mask, nullptr);
    execve(argv[0], argv.data(), envp.data());
    _exit(127);
  }
  close(fds[1]);
  slot.pid = pid;
  output_fd = fds[0];
  logger_->info("worker {} started: pid {}", slot.name, pid);
  return core::Status::Ok();
}

LocalWorkers::Death LocalWorkers::Watch(Slot& slot, int output_fd) {
  Death death;
  death.started = std::chrono::steady_clock::now();
  pid_t pid = 0;
  {
    std::lock_guard lock(slot.mutex);
    pid = slot.pid;
  }
  std::string partial;
  const auto take_line = [&](std::string_view line) {
    // Its own time stamp ("2026-01-31T12:00:00.000 ") goes: seepd's log line has one.
    if (line.size() > 24 && line[4] == '-' && line[10] == 'T' && line[23] == ' ') {
      line.remove_prefix(24);
    }
    const std::string printable = Printable(line);
    logger_->info("{}: {}", slot.name, printable);
    death.last_lines.push_back(printable);
    if (death.last_lines.size() > kLastLines) death.last_lines.pop_front();
  };
  const auto drain = [&](int timeout_ms) {
    pollfd readable{output_fd, POLLIN, 0};
    if (output_fd < 0 || poll(&readable, 1, timeout_ms) <= 0) return;
    char buffer[16384];
    const ssize_t n = read(output_fd, buffer, sizeof buffer);
    if (n <= 0) {  // end of output (the process closed it, or ended)
      close(output_fd);
      output_fd = -1;
      return;
    }
    partial.append(buffer, static_cast<std::size_t>(n));
    std::size_t start = 0;
    for (std::size_t end; (end = partial.find('\n', start)) != std::string::npos; start = end + 1) {
      take_line(std::string_view(partial).substr(start, end - start));
    }
    partial.erase(0, start);
    if (partial.size() > 4 * kLineBytes) {  // no newline for this long: a line of its own
      take_line(partial);
      partial.clear();
    }
  };
  auto next_check = std::chrono::steady_clock::now() + kJobCheck;
  bool terminated = false;  // sent SIGTERM for the shutdown
  bool killed_for_shutdown = false;
  for (;;) {
    drain(static_cast<int>(kPoll.count()));
    int status = 0;
    pid_t reaped = 0;
    {
      std::lock_guard lock(slot.mutex);
      reaped = waitpid(pid, &status, WNOHANG);
      if (reaped == pid) slot.pid = 0;
    }
    if (reaped == pid) {
      death.wait_status = status;
      break;
    }
    if (stopping_) {
      if (!terminated) {
        kill(pid, SIGTERM);
        terminated = true;
      }
      if (!killed_for_shutdown && kill_at_ms_ > 0 && SteadyMs() >= kill_at_ms_) {
        logger_->warn("worker {} (pid {}) still running at the shutdown's deadline: killed",
                      slot.name, pid);
        kill(pid, SIGKILL);
        killed_for_shutdown = true;
      }
    } else if (std::chrono::steady_clock::now() >= next_check) {
      next_check = std::chrono::steady_clock::now() + kJobCheck;
      if (death.reason == KillReason::kNone) CheckHeldJobs(slot, death);
      if (death.reason != KillReason::kNone) kill(pid, SIGKILL);
    }
  }
  // What it wrote last, up to its end.
  while (output_fd >= 0) drain(0);
  if (!partial.empty()) take_line(partial);
  return death;
}

void LocalWorkers::CheckHeldJobs(Slot& slot, Death& death) {
  pid_t pid = 0;
  {
    std::lock_guard lock(slot.mutex);
    pid = slot.pid;
  }
  if (pid <= 0) return;
  auto held = store_.RunningLeasedBy(LocalWorkerLeasePrefix(slot.name, pid));
  if (!held.ok()) {
    logger_->warn("worker {}: its jobs not checked: {}", slot.name, held.status().ToString());
    return;
  }
  const std::int64_t now = NowMs();
  const std::int64_t grace = options_.grace.count();
  for (const JobRecord& job : *held) {
    const std::int64_t running_ms = now - job.started_at_ms.value_or(now);
    const std::int64_t limit_ms = static_cast<std::int64_t>(options_.job_time_limit_s * 1000);
    if (job.cancel_requested) {
      // A cancel reaches the process within a heartbeat and stops the job at its next step;
      // in a set-up, or a step that does not end, it would wait for ever.
      const std::int64_t cancelled_at = death.cancel_seen.try_emplace(job.id, now).first->second;
      if (now - cancelled_at >= grace) {
        death.reason = KillReason::kCancel;
        death.reason_job = job.id;
        logger_->warn(
            "worker {} (pid {}): job {} was cancelled {} ms ago and is still running (in its "
            "set-up, or a step that does not end): the process is ended",
            slot.name, pid, job.id, now - cancelled_at);
        return;
      }
    }
    if (limit_ms > 0 && running_ms > limit_ms + grace) {
      death.reason = KillReason::kTimeLimit;
      death.reason_job = job.id;
      logger_->warn(
          "worker {} (pid {}): job {} has run {:.1f} s, past --job-time-limit-s {} (in its "
          "set-up, or a step that does not end): the process is ended",
          slot.name, pid, job.id, running_ms / 1000.0, options_.job_time_limit_s);
      return;
    }
  }
}

void LocalWorkers::Bury(const Slot& slot, pid_t pid, const Death& death) {
  const std::string how = DescribeWaitStatus(death.wait_status);
  auto held = store_.RunningLeasedBy(LocalWorkerLeasePrefix(slot.name, pid));
  if (!held.ok()) {
    logger_->error("worker {} (pid {}) {}; its jobs not found ({}): their leases run out",
                   slot.name, pid, how, held.status().ToString());
    return;
  }
  if (held->empty()) {
    logger_->warn("worker {} (pid {}) {} holding no job; restarted", slot.name, pid, how);
    return;
  }
  // The job it was running: the one seepd ended it for, else its newest claim (an older one is a
  // finished run whose end was being recorded).
  const auto culprit_it = death.reason == KillReason::kNone
                              ? std::prev(held->end())
                              : std::find_if(held->begin(), held->end(), [&](const JobRecord& j) {
                                  return j.id == death.reason_job;
                                });
  if (culprit_it == held->end()) {
    logger_->warn("worker {} (pid {}) {}; job {} it was ended for is no longer running", slot.name,
                  pid, how, death.reason_job);
    return;
  }
  const JobRecord& job = *culprit_it;
  const std::string last_lines =
      death.last_lines.empty() ? "none" : "\"" + Join(death.last_lines) + "\"";
  const std::string memory = options_.memory_limit_mb > 0
                                 ? fmt::format(
                                       "; the process was limited to {} MiB of address space "
                                       "(--job-memory-limit-mb)",
                                       options_.memory_limit_mb)
                                 : "";
  JobState state = JobState::kFailed;
  std::string code = "INTERNAL";
  std::string message;
  switch (death.reason) {
    case KillReason::kCancel:
      state = JobState::kCancelled;
      code = "CANCELLED";
      message = fmt::format(
          "cancelled by request; its worker process {} (pid {}) did not stop it within {} s "
          "of the cancel "
          "(in its set-up, or a step that does not end) and was ended; progress since its last "
          "checkpoint is lost",
          slot.name, pid, options_.grace.count() / 1000.0);
      break;
    case KillReason::kTimeLimit:
      code = "DEADLINE_EXCEEDED";
      message = fmt::format(
          "ran past --job-time-limit-s {} by more than {} s (in its set-up, or a step that does "
          "not end, where it cannot stop at a step boundary); its worker process {} (pid {}) "
          "was ended (its last progress stored: step {}). Its last log lines: {}",
          options_.job_time_limit_s, options_.grace.count() / 1000.0, slot.name, pid,
          job.progress.step, last_lines);
      break;
    case KillReason::kNone:
      message = fmt::format(
          "its worker process {} (pid {}) {} while running it (its last progress stored: step "
          "{}){}; seepd and its other jobs run on. Its last log lines: {}",
          slot.name, pid, how, job.progress.step, memory, last_lines);
      break;
  }
  const std::int64_t now = NowMs();
  const double wall_s = (now - job.started_at_ms.value_or(now)) / 1000.0;
  if (auto s = store_.Finish(job.id, job.lease_epoch, state, code, message, {}, wall_s, now);
      !s.ok()) {
    // Its lease was taken over meanwhile (rescued, resumed): the newer claim decides.
    logger_->warn("job {}: the death of its worker {} not recorded: {}", job.id, slot.name,
                  s.ToString());
    return;
  }
  if (auto s = store_.AddEvent(job.id, now, "WORKER_DIED", message); !s.ok()) {
    logger_->warn("job {}: event not stored: {}", job.id, s.ToString());
  }
  logger_->error("job {} {}: {}", job.id, state == JobState::kCancelled ? "cancelled" : "failed",
                 message);
  hub_.RecordChanged(job.id);
  hub_.Finished(job.id);
  for (const JobRecord& other : *held) {
    if (other.id != job.id) {
      logger_->warn("job {}: its worker {} {}; queued again once its lease runs out", other.id,
                    slot.name, how);
    }
  }
}

}  // namespace seep::service
