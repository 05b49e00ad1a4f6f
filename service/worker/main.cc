// seep-worker: a remote worker. It leases simulation jobs from a seepd over gRPC
// (seep.v1.WorkerService) and runs them with the very runner seepd's own workers use
// (service/jobs/job_runner.h) over a RemoteLedger: progress and heartbeats go up, checkpoints go
// up in chunks (and come down to resume), results and outcomes go up, each fenced by the lease
// epoch. It keeps nothing on disk: killed at any moment, it loses the work since the job's last
// checkpoint, and the coordinator's rescuer queues the job again when its lease expires.
// SIGINT/SIGTERM: running jobs stop at a step boundary, are checkpointed and given back.
// Started by a batch system (seepd --executor slurm), it names its Slurm job and node in every
// claim and ends by itself: after --max-jobs jobs, or when --exit-when-idle-s passes without work.
#include <semaphore.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <thread>

#include "connection.h"
#include "jobs/escaped_log.h"
#include "jobs/job_hub.h"
#include "jobs/job_runner.h"
#include "jobs/runner_flags.h"
#include "jobs/secure_random.h"
#include "worker/remote_ledger.h"

namespace {

sem_t g_stop_signalled;
volatile std::sig_atomic_t g_stopping = 0;

// Exit status when a second signal cuts the drain short (as seepd's).
constexpr int kExitShutdownForced = 3;

extern "C" void OnStopSignal(int) {
  if (g_stopping != 0) _exit(kExitShutdownForced);  // a second signal: at once
  g_stopping = 1;
  sem_post(&g_stop_signalled);  // async-signal-safe
}

struct Options {
  seep::client::Connection connection;
  double timeout_s = 10.0;
  seep::service::RunnerFlags runner;  // workers, threads, lease, checkpoints, log level
  std::string name;                   // the lease owner's prefix; default: the host name
  int max_jobs = 0;                   // 0: no limit
  double exit_when_idle_s = 0.0;      // 0: never
  double job_time_limit_s = 0.0;      // 0: none
  std::uint64_t memory_limit_mb = 0;  // 0: none
  bool supervised = false;            // started by seepd (--isolation process)
  std::string test_segfault_job;
  std::string test_hog_memory_job;
};

sem_t g_wake_signalled;

extern "C" void OnWakeSignal(int) { sem_post(&g_wake_signalled); }  // async-signal-safe

// The address space this process may take, so that a job that outgrows it fails alone (its
// allocation throws std::bad_alloc, or the process ends) instead of starving the machine. Said
// in the outcome of such a job.
std::optional<std::string> LimitMemory(std::uint64_t megabytes, bool supervised) {
  if (megabytes == 0) return std::string();
  rlimit limit{};
  limit.rlim_cur = limit.rlim_max = static_cast<rlim_t>(megabytes) << 20;
  if (setrlimit(RLIMIT_AS, &limit) != 0) return std::nullopt;
  return fmt::format("the worker process's address space is limited to {} MiB ({})", megabytes,
                     supervised ? "seepd --job-memory-limit-mb" : "seep-worker --memory-limit-mb");
}

// Where this worker runs when Slurm started it (its job id and node, from the environment Slurm
// gives a job), said in every claim; none outside Slurm.
std::optional<seep::service::WorkerPlacement> PlacementFromEnvironment() {
  const char* job = std::getenv("SLURM_JOB_ID");
  if (job == nullptr || *job == '\0') return std::nullopt;
  const char* node = std::getenv("SLURMD_NODENAME");
  return seep::service::WorkerPlacement{job, node == nullptr ? "" : node};
}

std::string HostName() {
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0 || host[0] == '\0') return "worker";
  return host;
}

int Run(Options& options) {
  auto logger = std::make_shared<spdlog::logger>(
      "seep-worker", std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  logger->set_formatter(seep::service::EscapingLogFormatter());
  logger->set_level(spdlog::level::from_str(options.runner.log_level));
  logger->flush_on(spdlog::level::info);
  if (const std::string problem = seep::client::LoadConnectionSecrets(options.connection);
      !problem.empty()) {
    std::fprintf(stderr, "seep-worker: %s\n", problem.c_str());
    return 2;
  }
  const auto owner_bits = seep::service::SecureRandomU64();
  if (!owner_bits.ok()) {
    logger->critical("{}", owner_bits.status().message());
    return 1;
  }
  const std::string owner =
      fmt::format("{}-{}-{:08x}", options.name.empty() ? HostName() : options.name, ::getpid(),
                  static_cast<std::uint32_t>(*owner_bits));

  const auto memory_limit_note = LimitMemory(options.memory_limit_mb, options.supervised);
  if (!memory_limit_note) {
    logger->critical("--memory-limit-mb {}: setrlimit(RLIMIT_AS) failed: {}",
                     options.memory_limit_mb, std::strerror(errno));
    return 2;
  }
  sem_init(&g_stop_signalled, 0, 0);
  // Supervised: seepd wakes an idle worker with SIGUSR1 when jobs are queued (it started this
  // process with the signal blocked, so none arriving before the handler is lost or fatal).
  std::jthread wake_listener;
  if (options.supervised) {
    sem_init(&g_wake_signalled, 0, 0);
    struct sigaction wake {};
    wake.sa_handler = OnWakeSignal;
    sigemptyset(&wake.sa_mask);
    wake.sa_flags = SA_RESTART;
    sigaction(SIGUSR1, &wake, nullptr);
  }
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  const seep::client::Connection& connection = options.connection;
  seep::service::RemoteLedger ledger(
      seep::client::OpenSeepdChannel(connection),
      [&connection](grpc::ClientContext* ctx) { seep::client::AddToken(connection, ctx); },
      std::chrono::milliseconds(static_cast<std::int64_t>(options.timeout_s * 1000)),
      PlacementFromEnvironment());
  seep::service::JobRunnerOptions runner_options = seep::service::RunnerOptionsFrom(options.runner);
  runner_options.build_id = SEEP_BUILD_ID;
  runner_options.lease_owner = owner;
  runner_options.max_jobs = options.max_jobs;
  runner_options.exit_when_idle =
      std::chrono::milliseconds(static_cast<std::int64_t>(options.exit_when_idle_s * 1000));
  runner_options.job_time_limit =
      std::chrono::milliseconds(static_cast<std::int64_t>(options.job_time_limit_s * 1000));
  runner_options.memory_limit_note = *memory_limit_note;
  runner_options.renew_during_setup = options.supervised;
  runner_options.test_segfault_job = options.test_segfault_job;
  runner_options.test_hog_memory_job = options.test_hog_memory_job;
  std::atomic<bool> work_done{false};
  runner_options.on_work_done = [&work_done] {
    work_done = true;
    sem_post(&g_stop_signalled);
  };
  seep::service::JobHub hub;  // nobody follows here: seepd's hub hears of progress through RPCs
  seep::service::JobRunner runner(ledger, /*store=*/nullptr, hub, runner_options, logger);
  logger->info(
      "seep-worker {} as {}: leasing jobs from {} ({}{}), {} at a time of {} thread(s), leases "
      "of {} s",
      SEEP_BUILD_ID, owner, connection.server,
      connection.tls || !connection.tls_ca.empty() ? "TLS" : "plaintext",
      connection.token.empty() ? "" : ", bearer token", options.runner.workers,
      runner_options.threads_per_job, options.runner.lease_s);
  runner.Start();
  if (options.supervised) {
    wake_listener = std::jthread([&runner](const std::stop_token& stop) {
      while (!stop.stop_requested()) {
        if (sem_wait(&g_wake_signalled) == 0 && !stop.stop_requested()) runner.Wake();
      }
    });
    sigset_t wake_signal;
    sigemptyset(&wake_signal);
    sigaddset(&wake_signal, SIGUSR1);
    pthread_sigmask(SIG_UNBLOCK, &wake_signal, nullptr);
  }
  while (sem_wait(&g_stop_signalled) != 0) {
  }  // EINTR: wait again
  if (work_done) {
    logger->info("stopping: its work is done");
  } else {
    logger->info(
        "stopping: running jobs stop at a step, are checkpointed and given back (a second signal "
        "exits at once)");
  }
  runner.Stop();
  if (wake_listener.joinable()) {
    wake_listener.request_stop();
    sem_post(&g_wake_signalled);
    wake_listener.join();  // before the runner it wakes is gone
  }
  logger->info("seep-worker stopped");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  CLI::App app{"seep-worker: runs seep jobs leased from a seepd (seepd --workers 0 runs none)"};
  app.add_option("--server", options.connection.server, "seepd address")
      ->envname("SEEP_SERVER")
      ->capture_default_str();
  app.add_option("--token", options.connection.token,
                 "bearer token of a seepd started with a token (visible in ps: prefer "
                 "SEEP_TOKEN or --token-file)")
      ->envname("SEEP_TOKEN");
  app.add_option("--token-file", options.connection.token_file,
                 "read the bearer token from this file (wins over --token and SEEP_TOKEN)");
  app.add_flag("--tls", options.connection.tls,
               "connect with TLS, trusting the system's root certificates");
  app.add_option("--tls-ca", options.connection.tls_ca,
                 "connect with TLS, trusting this PEM CA (or self-signed) certificate");
  app.add_option("--timeout", options.timeout_s,
                 "seconds each call may take (a checkpoint transfer ten times as long)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--workers", options.runner.workers, "jobs run at the same time")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  seep::service::AddRunnerFlags(
      app, options.runner,
      "seconds a job's lease lasts without a heartbeat; a worker that dies loses its jobs to the "
      "coordinator's rescuer this long after (must exceed the longest step or scene set-up)");
  app.add_option("--name", options.name,
                 "names this worker in leases and events (default: the host name); the pid and "
                 "a random suffix are added");
  app.add_option("--max-jobs", options.max_jobs,
                 "claim this many jobs in all, then exit once they ended (0: no limit; seepd's "
                 "Slurm executor starts one worker per job with 1)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--exit-when-idle-s", options.exit_when_idle_s,
                 "exit after finding no job to claim for this many seconds with none running (0: "
                 "never; for workers a batch system starts, so that an allocation ends when the "
                 "queue is empty)")
      ->check(CLI::Range(0.0, 1e7))
      ->capture_default_str();
  app.add_option("--job-time-limit-s", options.job_time_limit_s,
                 "wall seconds one claim of a job may run, set-up included, before it is stopped "
                 "and FAILED with DEADLINE_EXCEEDED (0: none)")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option("--memory-limit-mb", options.memory_limit_mb,
                 "address space this process may take, in MiB (setrlimit RLIMIT_AS): a job that "
                 "needs more fails RESOURCE_EXHAUSTED, naming it (0: none)")
      ->capture_default_str();
  // seepd's own worker processes (seepd --isolation process) only.
  app.add_flag("--supervised", options.supervised,
               "started by seepd, which watches it: wakes on SIGUSR1, renews a job's lease "
               "during its set-up (seepd ends a set-up past the time limit or a cancel)")
      ->group("");
  app.add_option("--test-segfault-job", options.test_segfault_job,
                 "TEST ONLY: a job of this name dies of SIGSEGV 1500 steps into its run")
      ->group("");
  app.add_option("--test-hog-memory-job", options.test_hog_memory_job,
                 "TEST ONLY: a job of this name allocates memory 1500 steps into its run until "
                 "an allocation fails (needs --memory-limit-mb)")
      ->group("");
  CLI11_PARSE(app, argc, argv);
  if (!options.test_hog_memory_job.empty() && options.memory_limit_mb == 0) {
    std::fprintf(stderr, "seep-worker: --test-hog-memory-job needs --memory-limit-mb\n");
    return 2;
  }
  try {
    return Run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "seep-worker: fatal: %s\n", e.what());
    return 1;
  }
}
