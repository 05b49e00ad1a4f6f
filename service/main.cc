// seepd: the seep job server. Flags, logging sinks, the store, the worker pool and the gRPC
// server; SIGINT/SIGTERM stop it gracefully (running jobs are left to resume on restart).
#include <fcntl.h>
#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/resource_quota.h>
#include <semaphore.h>
#include <spdlog/sinks/rotating_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <thread>

#include "codec/scene_codec.h"
#include "executor/local_workers.h"
#include "executor/slurm_executor.h"
#include "jobs/checkpoint_recovery.h"
#include "jobs/checkpoint_sweep.h"
#include "jobs/escaped_log.h"
#include "jobs/job_hub.h"
#include "jobs/job_runner.h"
#include "jobs/low_disk_watch.h"
#include "jobs/physics_pool.h"
#include "jobs/retention.h"
#include "jobs/runner_flags.h"
#include "jobs/secure_random.h"
#include "jobs/startup_recovery.h"
#include "jobs/store_ledger.h"
#include "jobs/test_crash_points.h"
#include "metrics/metrics_endpoint.h"
#include "metrics/service_metrics.h"
#include "rpc/bearer_auth.h"
#include "rpc/seep_service.h"
#include "rpc/undecodable_request.h"
#include "rpc/worker_service.h"
#include "seep/core/log.h"
#include "seep/core/threads.h"
#include "store/durable_files.h"
#include "store/job_store.h"

namespace {

sem_t g_stop_signalled;
volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void OnStopSignal(int sig) {
  g_stop_signal = sig;
  sem_post(&g_stop_signalled);  // async-signal-safe; a second post is the second signal
}

// Exit status of a seepd whose shutdown was cut short (a second signal, or the time limit): its
// running jobs stay RUNNING with their leases, and the next start queues them again.
constexpr int kExitShutdownForced = 3;

struct Options {
  std::string listen = "127.0.0.1:50051";
  std::string data_dir = "seep-data";
  std::string port_file;
  seep::service::RunnerFlags runner;  // workers, threads, lease, checkpoints, log level
  double job_time_limit_s = 0.0;      // 0: no limit
  std::string test_stall_job;         // test only
  int test_fail_final_writes = 0;     // test only
  std::string test_crash_job;         // test only
  std::string test_crash_at;          // test only: POINT:N (TestCrashPoints)
  std::string test_segfault_job;      // test only
  std::string test_hog_memory_job;    // test only
  // process: simulations run in seep-worker child processes (a crash fails the job only);
  // thread: on seepd's own threads (a crash takes seepd down).
  std::string isolation = "process";
  std::optional<std::uint64_t> job_memory_limit_mb;  // default: DefaultJobMemoryLimitMb
  std::string seep_worker;                           // default: DefaultWorkerPath
  int max_interruptions = 3;
  bool strict_permissions = false;  // refuse a data folder open to group or others
  std::string token_file;           // else SEEP_TOKEN; neither: no token
  std::string tls_cert;             // PEM; with tls_key, serve TLS
  std::string tls_key;
  int max_message_bytes = 64 << 20;
  std::size_t max_scene_bytes = seep::service::kDefaultMaxSceneBytes;
  bool accept_lost_database = false;         // start on an empty store beside checkpoint files
  bool recover_from_checkpoints = false;     // rebuild an empty store's jobs from the files
  std::uint64_t min_free_disk_mb = 256;      // kept free on the data folder's file system
  std::string test_free_disk_bytes_file;     // test only: the free space, read from this file
  double retain_days = 0.0;                  // 0: finished jobs are kept however old
  std::int64_t retain_checkpoint_bytes = 0;  // 0: no budget
  double retention_interval_s = 600.0;
  double shutdown_timeout_s = 60.0;
  std::size_t max_response_bytes = seep::service::kDefaultMaxResponseBytes;
  int rpc_threads = 200;
  int max_watch_streams = seep::service::kDefaultMaxWatchStreams;
  int max_streams_per_connection = 100;
  double keepalive_s = 30.0;
  std::string metrics_listen;  // empty: no metrics endpoint
  std::uint64_t max_checkpoint_bytes = seep::service::kDefaultMaxCheckpointUploadBytes;
  std::string executor = "local";  // local: seepd's own workers (and remote ones) only; slurm
  seep::service::SlurmExecutorOptions slurm;
  std::string slurm_extra;        // split on whitespace
  std::string slurm_worker_args;  // split on whitespace
  double slurm_poll_s = 5.0;
};

// Words separated by white space (sbatch's and seep-worker's extra arguments; no quoting).
std::vector<std::string> Words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> words;
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

// The address a Slurm job's worker dials: --slurm-server, else the listen address with the bound
// port, a wildcard host replaced by this host's name (a node cannot dial 0.0.0.0).
std::string WorkerServerAddress(const Options& options, int port) {
  if (!options.slurm.server.empty()) return options.slurm.server;
  const auto colon = options.listen.rfind(':');
  std::string host = colon == std::string::npos ? options.listen : options.listen.substr(0, colon);
  if (host.empty() || host == "0.0.0.0" || host == "[::]" || host == "::") {
    char name[256] = {};
    host = ::gethostname(name, sizeof name - 1) == 0 && name[0] != '\0' ? name : "localhost";
  }
  return host + ":" + std::to_string(port);
}

// seep-worker beside this seepd (the build tree and an installation alike).
std::string DefaultWorkerPath() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return "seep-worker";
  const auto beside = self.parent_path() / "seep-worker";
  if (std::filesystem::exists(beside)) return beside.string();
  const auto in_build_tree = self.parent_path() / "worker" / "seep-worker";
  return std::filesystem::exists(in_build_tree) ? in_build_tree.string() : "seep-worker";
}

// Waits for the drain to finish (`drained`), a second signal or the time limit; the last two end
// the process at once, saying why.
void AwaitDrain(const std::atomic<bool>& drained, double timeout_s, spdlog::logger& logger) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<std::int64_t>(timeout_s * 1000));
  while (!drained) {
    timespec until{};
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_nsec += 100'000'000;
    if (until.tv_nsec >= 1'000'000'000) {
      until.tv_sec += 1;
      until.tv_nsec -= 1'000'000'000;
    }
    const bool second_signal = sem_timedwait(&g_stop_signalled, &until) == 0;
    const bool too_long = std::chrono::steady_clock::now() > deadline;
    if (!second_signal && !too_long) continue;
    if (drained) return;
    if (second_signal) {
      logger.warn(
          "second signal {} received: exiting now, without waiting for running jobs to stop (they "
          "continue from their newest checkpoint at the next start)",
          static_cast<int>(g_stop_signal));
    } else {
      logger.error(
          "shutdown did not finish within {} s (--shutdown-timeout-s): exiting now; running jobs "
          "continue from their newest checkpoint at the next start",
          timeout_s);
    }
    logger.flush();
    std::_Exit(kExitShutdownForced);
  }
}

// The gRPC server's limits: threads (each call, and each open WatchJob stream, holds one),
// streams per connection, message sizes and keepalive (dead peers are noticed and dropped).
void ApplyServerLimits(const Options& options, grpc::ServerBuilder& builder) {
  grpc::ResourceQuota quota("seepd");
  quota.SetMaxThreads(options.rpc_threads);  // beyond: RESOURCE_EXHAUSTED
  builder.SetResourceQuota(quota);
  // The sync server keeps at most MAX_POLLERS idle threads and starts a new one whenever a call
  // finds none polling; with gRPC's default of 2, a hundred workers calling once a second made
  // seepd create and end some 45 threads a second. Idle pollers only wait on the queue.
  builder.SetSyncServerOption(grpc::ServerBuilder::SyncServerOption::MIN_POLLERS, 2);
  builder.SetSyncServerOption(grpc::ServerBuilder::SyncServerOption::MAX_POLLERS,
                              std::min(options.rpc_threads, 32));
  // Larger requests are refused by gRPC itself with RESOURCE_EXHAUSTED before any handler runs.
  builder.SetMaxReceiveMessageSize(options.max_message_bytes);
  // GetJobFields checks its own limit first, with the figures; this is the backstop.
  builder.SetMaxSendMessageSize(static_cast<int>(
      std::min<std::size_t>(options.max_response_bytes + (1u << 20),
                            static_cast<std::size_t>(std::numeric_limits<int>::max()))));
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, options.max_streams_per_connection);
  const int keepalive_ms = static_cast<int>(options.keepalive_s * 1000);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, keepalive_ms);
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, std::min(keepalive_ms, 10000));
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
  // Clients may ping as often as every 10 s (watchers on idle jobs keep their streams alive).
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, 10000);
  // Undecodable request bytes: INVALID_ARGUMENT naming the message, not gRPC's empty INTERNAL.
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> creators;
  creators.push_back(std::make_unique<seep::service::UndecodableRequestInterceptorFactory>());
  builder.experimental().SetInterceptorCreators(std::move(creators));
}

// Loopback addresses and unix sockets are the only places where plaintext without a token is
// the expected set-up; anything else gets a warning.
bool IsLoopback(const std::string& listen) {
  if (listen.rfind("unix:", 0) == 0) return true;
  const auto colon = listen.rfind(':');
  std::string host = colon == std::string::npos ? listen : listen.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

// Whole-file read for PEM files; nullopt if the file cannot be opened.
std::optional<std::string> ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream content;
  content << in.rdbuf();
  return content.str();
}

// TLS credentials from --tls-cert/--tls-key, plaintext without them; nullptr after logging why.
std::shared_ptr<grpc::ServerCredentials> MakeServerCredentials(const Options& options,
                                                               spdlog::logger& logger) {
  if (options.tls_cert.empty()) return grpc::InsecureServerCredentials();
  const auto cert = ReadFile(options.tls_cert);
  const auto key = ReadFile(options.tls_key);
  if (!cert || cert->find("-----BEGIN") == std::string::npos) {
    logger.critical("--tls-cert {}: cannot read a PEM certificate from it", options.tls_cert);
    return nullptr;
  }
  if (!key || key->find("-----BEGIN") == std::string::npos) {
    logger.critical("--tls-key {}: cannot read a PEM private key from it", options.tls_key);
    return nullptr;
  }
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({*key, *cert});
  return grpc::SslServerCredentials(ssl);
}

// The token from --token-file, else from SEEP_TOKEN; nullopt-in-Result means no token at all.
seep::core::Result<std::optional<seep::service::BearerAuth>> LoadToken(const Options& options) {
  if (!options.token_file.empty()) {
    auto auth = seep::service::BearerAuth::FromFile(options.token_file);
    if (!auth.ok()) return auth.status();
    return std::optional<seep::service::BearerAuth>(std::move(*auth));
  }
  const char* env = std::getenv("SEEP_TOKEN");
  if (env == nullptr || *env == '\0') return std::optional<seep::service::BearerAuth>();
  auto auth = seep::service::BearerAuth::FromToken(env);
  if (!auth.ok()) {
    return seep::core::InvalidArgument("SEEP_TOKEN: " + auth.status().message());
  }
  return std::optional<seep::service::BearerAuth>(std::move(*auth));
}

std::shared_ptr<spdlog::logger> MakeLogger(const Options& options) {
  auto console = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  auto file = std::make_shared<spdlog::sinks::rotating_file_sink_mt>(
      (std::filesystem::path(options.data_dir) / "seepd.log").string(), 10 * 1024 * 1024, 5);
  auto logger = std::make_shared<spdlog::logger>("seepd", spdlog::sinks_init_list{console, file});
  logger->set_formatter(seep::service::EscapingLogFormatter());
  logger->set_level(spdlog::level::from_str(options.runner.log_level));
  logger->flush_on(spdlog::level::info);
  return logger;
}

// Written after the port is bound, via rename, so a reader never sees a partial number.
bool WritePortFile(const std::string& path, int port) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << port << "\n";
    if (!out.flush()) return false;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  return !ec;
}

// Exit status of a seepd that finds its data folder held by another one.
constexpr int kExitDataDirInUse = 75;
// The store holds no job beside checkpoint files (jobs/checkpoint_sweep.h): EX_DATAERR.
constexpr int kExitLostDatabase = 65;

// One seepd per data folder: an exclusive flock on <data-dir>/seepd.lock, held (the descriptor
// left open) for the life of the process and released by the kernel however it ends, kill -9
// included. The file holds the holder's pid, for the message of the next one. Returns the
// descriptor, or -1 after printing why (to stderr only: a refused seepd writes nothing into the
// folder, not even its log).
int LockDataDir(const std::string& data_dir, bool& in_use) {
  in_use = false;
  const std::string path = (std::filesystem::path(data_dir) / "seepd.lock").string();
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) {
    std::fprintf(stderr, "seepd: --data-dir %s: cannot open %s: %s\n", data_dir.c_str(),
                 path.c_str(), std::strerror(errno));
    return -1;
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    if (error == EWOULDBLOCK) {
      char pid[32] = {};
      const ssize_t n = ::pread(fd, pid, sizeof pid - 1, 0);
      std::string holder = n > 0 ? std::string(pid, static_cast<std::size_t>(n)) : "";
      while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
      std::fprintf(stderr,
                   "seepd: --data-dir %s is in use by another seepd (pid %s, lock %s); stop it "
                   "or choose another --data-dir. Nothing was changed.\n",
                   data_dir.c_str(), holder.empty() ? "unknown" : holder.c_str(), path.c_str());
      in_use = true;
    } else {
      std::fprintf(stderr, "seepd: --data-dir %s: cannot lock %s: %s\n", data_dir.c_str(),
                   path.c_str(), std::strerror(error));
    }
    ::close(fd);
    return -1;
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd, 0) != 0 ||
      ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
    std::fprintf(stderr, "seepd: --data-dir %s: cannot write %s: %s\n", data_dir.c_str(),
                 path.c_str(), std::strerror(errno));
    ::close(fd);
    return -1;
  }
  return fd;
}

// The data folder's bits for group and others when it lets them in (0 when it does not, or when
// it cannot be read).
mode_t LooseBits(const std::string& data_dir) {
  struct stat st {};
  if (::stat(data_dir.c_str(), &st) != 0) return 0;
  return st.st_mode & 077;
}

// What an older seepd (or another umask) left readable by others: the store, its journal, the
// log and the lock file are its owner's alone.
void TightenFiles(const std::string& data_dir) {
  for (const char* name :
       {"seep.db", "seep.db-wal", "seep.db-shm", "seep.db-journal", "seepd.log", "seepd.lock"}) {
    const std::string path = (std::filesystem::path(data_dir) / name).string();
    ::chmod(path.c_str(), 0600);  // absent files are fine
  }
}

int Run(const Options& options) {
  // Everything seepd creates (the store and its -wal/-shm, the log, the port file, checkpoint
  // files and folders) is its owner's alone, whatever umask it was started with: they hold every
  // job's scene and state.
  ::umask(077);
  // A folder seepd did not create may let group or others in: said in the log, or (with
  // --strict-permissions) refused before anything is written into it.
  const mode_t loose = LooseBits(options.data_dir);
  if (loose != 0 && options.strict_permissions) {
    std::fprintf(stderr,
                 "seepd: --data-dir %s is open to group or others (mode bits %03o); chmod 700 it, "
                 "or start without --strict-permissions. Nothing was changed.\n",
                 options.data_dir.c_str(), static_cast<unsigned>(loose));
    return 2;
  }
  // Private to its owner (0700) when seepd creates it: it holds every job's scene and state.
  if (const auto created = seep::service::CreateDirectoriesDurably(options.data_dir);
      !created.ok()) {
    std::fprintf(stderr, "seepd: --data-dir %s: %s\n", options.data_dir.c_str(),
                 created.message().c_str());
    return 2;
  }
  // Before anything else touches the folder (log, database, recovery of interrupted jobs).
  bool in_use = false;
  if (LockDataDir(options.data_dir, in_use) < 0) return in_use ? kExitDataDirInUse : 2;
  TightenFiles(options.data_dir);
  auto logger = MakeLogger(options);
  seep::core::SetLogger(logger->clone("core"));
  if (loose != 0) {
    logger->warn(
        "--data-dir {} is open to group or others (mode bits {:03o}): they may read every job's "
        "scene and state; chmod 700 it (--strict-permissions refuses such a folder)",
        options.data_dir, static_cast<unsigned>(loose));
  }

  // SIGINT/SIGTERM wake the shutdown thread through a semaphore posted by a handler. Not
  // sigwait: libraries start threads before main (OpenBLAS, under CHOLMOD, starts its pool
  // when loaded) whose masks leave the signals unblocked, and the kernel may deliver to any of
  // them, so the disposition itself must be ours. The threads started here block the signals,
  // but for the shutdown thread (signal_waiter below), which opens them for itself.
  if (sem_init(&g_stop_signalled, 0, 0) != 0) {
    logger->critical("cannot create the shutdown semaphore");
    return 1;
  }
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  const std::string db_path = (std::filesystem::path(options.data_dir) / "seep.db").string();
  auto store = seep::service::JobStore::Open(
      db_path, {options.min_free_disk_mb << 20, options.test_free_disk_bytes_file});
  if (!store.ok()) {
    logger->critical("cannot open the job store {}: {}", db_path, store.status().ToString());
    return 1;
  }
  // Unique per process: any RUNNING lease held by another owner belongs to a previous seepd.
  const auto owner_bits = seep::service::SecureRandomU64();
  if (!owner_bits.ok()) {
    logger->critical("{}", owner_bits.status().message());
    return 1;
  }
  const std::string lease_owner = fmt::format("seepd-{}-{:016x}", ::getpid(), *owner_bits);
  // On a disk too full for it, put off (seepd serves read-only until space is back).
  seep::service::StartupRecovery recovery(**store, lease_owner, options.max_interruptions, logger);
  if (auto recovered = recovery.Run(); !recovered.ok()) {
    logger->critical("recovery failed: {}", recovered.ToString());
    return 1;
  }
  // No worker runs yet: whatever a crash left in the checkpoint folder can go.
  const std::filesystem::path checkpoints_dir =
      std::filesystem::path(options.data_dir) / "checkpoints";
  if (options.recover_from_checkpoints) {
    auto recovered = seep::service::RecoverFromCheckpoints(**store, checkpoints_dir, *logger);
    if (!recovered.ok()) {
      logger->critical("{}", recovered.status().message());
      std::fprintf(stderr, "seepd: %s\n", recovered.status().message().c_str());
      return kExitLostDatabase;
    }
    logger->info(
        "recovery: {} job(s) rebuilt from {} checkpoint file(s), queued to continue from their "
        "newest checkpoints; {} job folder(s) could not be rebuilt (in lost-checkpoints)",
        recovered->jobs, recovered->checkpoint_files, recovered->unrecoverable.size());
  }
  if (auto swept = seep::service::SweepCheckpointFolder(**store, checkpoints_dir, *logger,
                                                        options.accept_lost_database);
      !swept.ok()) {
    // A lost database: the files are the jobs' only state, and nothing may run over them.
    if (swept.status().code() == seep::core::StatusCode::kFailedPrecondition) {
      logger->critical("{}", swept.status().message());
      std::fprintf(stderr, "seepd: %s\n", swept.status().message().c_str());
      return kExitLostDatabase;
    }
    logger->warn("checkpoint sweep skipped: {}", swept.status().message());
  }
  seep::service::RetentionPolicy retention_policy;
  retention_policy.max_age_ms = static_cast<std::int64_t>(options.retain_days * 86'400'000.0);
  retention_policy.max_checkpoint_bytes = options.retain_checkpoint_bytes;
  seep::service::Retention retention(
      **store, retention_policy,
      std::chrono::milliseconds(static_cast<std::int64_t>(options.retention_interval_s * 1000)),
      logger);
  retention.RunOnce();  // before any worker: nothing changes under it

  auto token = LoadToken(options);
  if (!token.ok()) {
    logger->critical("{}", token.status().message());
    return 2;
  }
  if (options.max_watch_streams >= options.rpc_threads) {
    logger->critical(
        "--max-watch-streams {} must be below --rpc-threads {}: each open stream holds a server "
        "thread, and the other calls need some too",
        options.max_watch_streams, options.rpc_threads);
    return 2;
  }
  seep::service::TestCrashPoints crash_points;
  if (!options.test_crash_at.empty()) {
    if (auto armed = crash_points.Arm(options.test_crash_at); !armed.ok()) {
      logger->critical("{}", armed.message());
      return 2;
    }
    logger->warn("test hook --test-crash-at {} is on: not for production", options.test_crash_at);
  }
  auto credentials = MakeServerCredentials(options, *logger);
  if (!credentials) return 2;
  const bool tls = !options.tls_cert.empty();
  const bool authenticated = token->has_value();
  if (!IsLoopback(options.listen)) {
    if (!tls && !authenticated) {
      logger->warn(
          "listening on {} (not loopback) without TLS or a token: anyone who can reach it can "
          "submit and cancel jobs (see --tls-cert/--tls-key, --token-file)",
          options.listen);
    } else if (!tls) {
      logger->warn("listening on {} (not loopback) without TLS: the token travels in clear text",
                   options.listen);
    }
  }

  seep::service::JobHub hub;
  seep::service::JobRunnerOptions runner_options = seep::service::RunnerOptionsFrom(options.runner);
  runner_options.build_id = SEEP_BUILD_ID;
  runner_options.lease_owner = lease_owner;
  runner_options.job_time_limit =
      std::chrono::milliseconds(static_cast<std::int64_t>(options.job_time_limit_s * 1000));
  runner_options.test_stall_job = options.test_stall_job;
  runner_options.test_fail_final_writes = options.test_fail_final_writes;
  runner_options.test_crash_job = options.test_crash_job;
  runner_options.max_interruptions = options.max_interruptions;
  const bool isolated = options.isolation == "process" && options.runner.workers > 0;
  if (!options.test_hog_memory_job.empty() &&
      (!isolated || options.job_memory_limit_mb.value_or(1) == 0)) {
    logger->critical("--test-hog-memory-job needs worker processes with a memory limit");
    return 2;
  }
  if (isolated && (!options.test_stall_job.empty() || options.test_fail_final_writes > 0)) {
    logger->critical(
        "--test-stall-job and --test-fail-final-writes act on seepd's own threads: they need "
        "--isolation thread");
    return 2;
  }
  runner_options.test_segfault_job = options.test_segfault_job;  // on seepd's threads: its end
  if (!options.test_stall_job.empty() || options.test_fail_final_writes > 0 ||
      !options.test_crash_job.empty() || !options.test_segfault_job.empty() ||
      !options.test_hog_memory_job.empty()) {
    logger->warn(
        "test hooks (--test-stall-job '{}', --test-fail-final-writes {}, --test-crash-job '{}', "
        "--test-segfault-job '{}', --test-hog-memory-job '{}') are on: not for production",
        options.test_stall_job, options.test_fail_final_writes, options.test_crash_job,
        options.test_segfault_job, options.test_hog_memory_job);
  }
  seep::service::ServiceMetrics metrics;
  runner_options.metrics = &metrics;
  runner_options.checkpoints.on_written = [&metrics](std::int64_t bytes, double seconds) {
    metrics.RecordCheckpoint(bytes, seconds);
  };
  if (crash_points.armed()) runner_options.crash_points = &crash_points;
  // Where seepd's own workers, and remote ones through the WorkerService, keep jobs' progress.
  // Isolated, seepd's own threads run only calibrations (one at a time), which need its store;
  // the simulations run in the worker processes, through the WorkerService.
  const int simulation_workers = options.runner.workers;
  if (isolated) runner_options.workers = 1;
  seep::service::StoreLedger ledger(
      **store, checkpoints_dir, logger, crash_points.armed() ? &crash_points : nullptr,
      isolated ? std::optional(seep::service::JobKind::kCalibration) : std::nullopt);
  seep::service::JobRunner runner(ledger, &**store, hub, runner_options, logger);
  // The memory each job may use: what each worker process is limited to, and what the admission
  // estimate at submit compares a scene with (on seepd's own threads, nothing limits a job).
  const std::uint64_t job_memory_limit_mb =
      isolated ? options.job_memory_limit_mb.value_or(
                     seep::service::DefaultJobMemoryLimitMb(simulation_workers))
               : 0;
  // Where the worker processes dial seepd (computed once: it names the socket it listens on).
  const std::string worker_socket =
      seep::service::LocalWorkerSocketAddress(options.data_dir, *owner_bits);
  std::optional<seep::service::LocalWorkers> local_workers;
  if (isolated) {
    seep::service::LocalWorkersOptions local;
    local.worker_path = options.seep_worker.empty() ? DefaultWorkerPath() : options.seep_worker;
    local.server = worker_socket;
    local.count = simulation_workers;
    local.runner = options.runner;
    local.runner.threads_per_job = runner_options.threads_per_job;
    if (token->has_value()) local.token = (*token)->token();
    local.memory_limit_mb = job_memory_limit_mb;
    local.job_time_limit_s = options.job_time_limit_s;
    if (!options.test_crash_job.empty()) {
      local.extra_args.insert(local.extra_args.end(), {"--test-crash-job", options.test_crash_job});
    }
    if (!options.test_hog_memory_job.empty()) {
      local.extra_args.insert(local.extra_args.end(),
                              {"--test-hog-memory-job", options.test_hog_memory_job});
    }
    if (!options.test_segfault_job.empty()) {
      local.extra_args.insert(local.extra_args.end(),
                              {"--test-segfault-job", options.test_segfault_job});
    }
    local_workers.emplace(**store, hub, std::move(local), logger);
  }
  // GetJobFields' physics: one request at a time with a job's thread budget, a few more waiting.
  seep::service::PhysicsPool physics(/*threads=*/1, runner_options.threads_per_job,
                                     /*max_waiting=*/16);
  // --executor slurm: batch jobs that start seep-worker, sized to the queue (started once the
  // port is known).
  std::optional<seep::service::SlurmExecutor> slurm;
  if (options.executor == "slurm") {
    seep::service::SlurmExecutorOptions slurm_options = options.slurm;
    slurm_options.extra = Words(options.slurm_extra);
    slurm_options.worker_args = Words(options.slurm_worker_args);
    if (slurm_options.worker_path.empty()) slurm_options.worker_path = DefaultWorkerPath();
    slurm_options.poll_interval =
        std::chrono::milliseconds(static_cast<std::int64_t>(options.slurm_poll_s * 1000));
    slurm_options.runner = options.runner;
    if (token->has_value()) slurm_options.token = (*token)->token();
    slurm.emplace(**store, options.data_dir, std::move(slurm_options), logger);
  }
  const auto wake_executors = [&] {
    runner.Wake();
    if (local_workers) local_workers->Wake();
    if (slurm) slurm->Wake();
  };
  seep::service::LowDiskWatch low_disk_watch(**store, recovery, wake_executors, logger);
  seep::service::SeepServiceImpl service(
      **store, hub, physics, SEEP_BUILD_ID,
      {wake_executors,
       [&](const std::string& id) {
         runner.CancelRunning(id);
         if (slurm) slurm->Wake();
       }},
      logger,
      {authenticated ? &**token : nullptr, options.max_scene_bytes, options.max_response_bytes,
       options.max_watch_streams, job_memory_limit_mb << 20},
      &metrics);
  // Remote workers (seep-worker) lease jobs through it, with the same token.
  seep::service::WorkerServiceImpl worker_service(
      **store, ledger, hub, logger,
      {authenticated ? &**token : nullptr, options.max_checkpoint_bytes}, &metrics);
  // Scraped on the endpoint's own threads: the store's counts are read at each scrape.
  seep::service::MetricsEndpoint metrics_endpoint([&] {
    seep::service::MetricsSnapshotGauges gauges;
    if (auto counts = (*store)->CountByState(); counts.ok()) {
      for (const auto& [state, count] : *counts) {
        gauges.jobs_by_state.emplace_back(seep::service::JobStateName(state), count);
      }
    } else {
      logger->warn("metrics: jobs not counted: {}", counts.status().ToString());
    }
    gauges.watch_streams = hub.followers();
    return metrics.Render(gauges);
  });

  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(options.listen, credentials, &port);
  // The worker processes' own door: a socket in the data folder (0700), which --listen's TLS and
  // address do not concern; the token is still required when there is one.
  if (isolated) {
    builder.AddListeningPort(worker_socket, grpc::InsecureServerCredentials());
  }
  ApplyServerLimits(options, builder);
  builder.RegisterService(&service);
  builder.RegisterService(&worker_service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) {
    logger->critical("cannot listen on {} (--listen{})", options.listen,
                     tls ? "; or --tls-cert/--tls-key do not form a valid pair" : "");
    return 1;
  }
  server->GetHealthCheckService()->SetServingStatus(true);
  if (isolated) {
    // The worker processes' socket: its owner's alone, as every file seepd writes (gRPC made it
    // with the mode the umask left, with execute bits a socket does not need).
    if (worker_socket.rfind("unix:", 0) == 0) ::chmod(worker_socket.c_str() + 5, 0600);
  }
  logger->info(
      "seepd {} listening on {} (port {}), data in {}, {} worker(s) of {} thread(s){}",
      SEEP_BUILD_ID, options.listen, port, options.data_dir, simulation_workers,
      runner_options.threads_per_job,
      !isolated ? std::string(" on seepd's own threads")
      : job_memory_limit_mb == 0
          ? std::string(", each a seep-worker process")
          : fmt::format(", each a seep-worker process of at most {} MiB", job_memory_limit_mb));
  logger->info("transport {}; {}; requests up to {} bytes, scenes up to {} bytes",
               tls ? "TLS" : "plaintext",
               authenticated ? "bearer token required for seep.v1.SeepService (health stays open)"
                             : "no token required",
               options.max_message_bytes, options.max_scene_bytes);
  logger->info(
      "limits: {} RPC threads, {} watch streams, {} streams per connection, keepalive every {} "
      "s, field responses up to {} bytes",
      options.rpc_threads, options.max_watch_streams, options.max_streams_per_connection,
      options.keepalive_s, options.max_response_bytes);
  if (!options.metrics_listen.empty()) {
    if (auto started = metrics_endpoint.Start(options.metrics_listen); !started.ok()) {
      logger->critical("{}", started.message());
      return 2;
    }
    logger->info("metrics for Prometheus on http://{}:{}/metrics",
                 options.metrics_listen.substr(0, options.metrics_listen.rfind(':')),
                 metrics_endpoint.port());
  }
  // Before the port file: a seepd that cannot reach Slurm is not ready to serve.
  if (slurm) {
    // The workers dial the bound port (--listen may have asked for port 0).
    slurm->SetServer(WorkerServerAddress(options, port));
    if (auto started = slurm->Start(); !started.ok()) {
      logger->critical("{}", started.message());
      return 2;
    }
  }
  if (!options.port_file.empty() && !WritePortFile(options.port_file, port)) {
    logger->critical("cannot write --port-file {}", options.port_file);
    return 1;
  }
  if (local_workers) {
    if (auto started = local_workers->Start(); !started.ok()) {
      logger->critical("{}", started.message());
      return 2;
    }
  }
  runner.Start();
  retention.Start();
  low_disk_watch.Start();

  std::thread signal_waiter([&] {
    // This thread takes the signals itself: every other thread of ours blocks them, and the
    // library threads that leave them open are not always there (OpenBLAS starts no pool on a
    // one-CPU machine or under taskset -c 0, and seepd then ignored SIGTERM for good). The drain
    // thread started below inherits this mask, which is as good.
    pthread_sigmask(SIG_UNBLOCK, &signals, nullptr);
    while (sem_wait(&g_stop_signalled) != 0) {
    }  // EINTR: wait again
    logger->info(
        "signal {} received: shutting down (health NOT_SERVING; running jobs stop at a step and "
        "are checkpointed; at most {} s, or at once on a second signal)",
        static_cast<int>(g_stop_signal), options.shutdown_timeout_s);
    // Probes see NOT_SERVING for the whole drain, while calls are still answered.
    server->GetHealthCheckService()->SetServingStatus(false);
    hub.Close();
    std::atomic<bool> drained{false};
    std::thread drain([&] {
      // Batch jobs already submitted keep running: their workers reconnect to the next seepd.
      if (slurm) slurm->Stop();
      retention.Stop();
      // The worker processes give their jobs back through the server, which still serves.
      if (local_workers) {
        local_workers->Stop(std::chrono::milliseconds(
            static_cast<std::int64_t>(options.shutdown_timeout_s * 1000 * 0.8)));
      }
      low_disk_watch.Stop();
      runner.Stop();
      server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(5));
      drained = true;
    });
    AwaitDrain(drained, options.shutdown_timeout_s, *logger);
    drain.join();
  });
  server->Wait();
  signal_waiter.join();
  metrics_endpoint.Stop();
  logger->info("seepd stopped");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  CLI::App app{"seepd: the seep seepage-simulation job server"};
  app.add_option("--listen", options.listen, "address:port to serve on (port 0 picks a free one)")
      ->capture_default_str();
  app.add_option("--data-dir", options.data_dir, "folder for the SQLite database and logs")
      ->capture_default_str();
  app.add_option("--workers", options.runner.workers,
                 "jobs run at the same time by seepd itself (0: a pure coordinator, whose jobs "
                 "seep-worker processes run)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  seep::service::AddRunnerFlags(
      app, options.runner,
      "seconds a job's lease lasts without progress; then the rescuer queues the job again (must "
      "exceed the longest step or scene set-up)");
  app.add_flag("--strict-permissions", options.strict_permissions,
               "refuse to start on a data folder open to group or others (else a warning in the "
               "log)");
  app.add_option("--port-file", options.port_file,
                 "write the bound port to this file once serving (for scripts and tests)");
  app.add_option("--job-time-limit-s", options.job_time_limit_s,
                 "wall seconds one run of a job may take before it is FAILED with "
                 "DEADLINE_EXCEEDED (checkpointed first; 0 = no limit)")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option(
         "--test-stall-job", options.test_stall_job,
         "TEST ONLY: the first worker to run a job of this name hangs 1500 steps into its run "
         "until it loses the lease")
      ->group("");  // hidden from --help
  app.add_option("--max-interruptions", options.max_interruptions,
                 "interruptions in a row without progress (crashes, dead or hung workers; not "
                 "shutdowns) after which a job is FAILED instead of run again")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--test-crash-job", options.test_crash_job,
                 "TEST ONLY: a worker running a job of this name ends seepd 1500 steps into its "
                 "run")
      ->group("");
  app.add_option("--test-crash-at", options.test_crash_at,
                 "TEST ONLY: POINT:N, seepd kills itself (SIGKILL) the N-th time it passes POINT: "
                 "checkpoint-file (a file written, not yet recorded) or final-state (a finished "
                 "job's final state ready, its success not yet recorded)")
      ->group("");
  app.add_option("--test-segfault-job", options.test_segfault_job,
                 "TEST ONLY: a worker running a job of this name dies of SIGSEGV 1500 steps into "
                 "its run")
      ->group("");
  app.add_option("--test-hog-memory-job", options.test_hog_memory_job,
                 "TEST ONLY: a worker process running a job of this name allocates memory 1500 "
                 "steps into its run until its memory limit stops it")
      ->group("");
  app.add_option("--isolation", options.isolation,
                 "process: jobs run in seep-worker child processes, so that one that crashes, "
                 "aborts or runs out of memory fails alone (FAILED, naming the cause); thread: on "
                 "seepd's own threads (a crash takes seepd down; calibrations always run there)")
      ->check(CLI::IsMember({"process", "thread"}))
      ->capture_default_str();
  app.add_option("--job-memory-limit-mb", options.job_memory_limit_mb,
                 "address space of each worker process in MiB (--isolation process; setrlimit "
                 "RLIMIT_AS): a job that needs more fails RESOURCE_EXHAUSTED (default: 90 % of "
                 "the machine's memory shared out among --workers, at least 1024; 0: none)");
  app.add_option("--seep-worker", options.seep_worker,
                 "the seep-worker binary that --isolation process starts (default: the one beside "
                 "this seepd)");
  app.add_option("--test-fail-final-writes", options.test_fail_final_writes,
                 "TEST ONLY: the first N tries of writing a finished job's result fail")
      ->check(CLI::NonNegativeNumber)
      ->group("");
  app.add_option("--token-file", options.token_file,
                 "require 'authorization: Bearer <token>' on every SeepService call, the token "
                 "read from this file (mode 600); without it, SEEP_TOKEN is used if set");
  auto* cert =
      app.add_option("--tls-cert", options.tls_cert, "serve TLS with this PEM certificate");
  auto* key = app.add_option("--tls-key", options.tls_key, "the PEM private key of --tls-cert");
  cert->needs(key);
  key->needs(cert);
  app.add_option("--max-message-bytes", options.max_message_bytes,
                 "largest request accepted (larger: RESOURCE_EXHAUSTED)")
      ->check(CLI::Range(4096, std::numeric_limits<int>::max()))
      ->capture_default_str();
  app.add_option("--max-scene-bytes", options.max_scene_bytes,
                 "largest serialized scene accepted (larger: INVALID_ARGUMENT, nothing stored)")
      ->check(CLI::Range(std::size_t{1024}, std::size_t{1} << 31))
      ->capture_default_str();
  app.add_flag("--accept-lost-database", options.accept_lost_database,
               "start on an empty store although checkpoint files exist (its database was lost): "
               "the files move to <data-dir>/lost-checkpoints, and nothing is deleted");
  app.add_flag("--recover-from-checkpoints", options.recover_from_checkpoints,
               "rebuild the jobs of an empty store (its database was lost) from the checkpoint "
               "files in <data-dir>/checkpoints and lost-checkpoints: each is queued under its id "
               "and continues from its newest checkpoint (labels, priority and results are not in "
               "the files); refused on a store that holds jobs")
      ->excludes("--accept-lost-database");
  app.add_option("--min-free-disk-mb", options.min_free_disk_mb,
                 "MiB kept free on the data folder's file system: below it submits are refused "
                 "(RESOURCE_EXHAUSTED), no job starts, a running job fails at its next "
                 "checkpoint (resumable), the WAL gives its space back, and reads go on; seepd "
                 "started below it serves read-only until space is freed (0 = no threshold)")
      ->check(CLI::Range(std::uint64_t{0}, std::uint64_t{1} << 40))
      ->capture_default_str();
  app.add_option("--test-free-disk-bytes-file", options.test_free_disk_bytes_file,
                 "TEST ONLY: read the data folder's free space (bytes) from this file instead of "
                 "the file system")
      ->group("");
  app.add_option("--retain-days", options.retain_days,
                 "delete finished jobs (with their checkpoints) this many days after they "
                 "finished; fractions allowed (0 = keep them)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  app.add_option("--retain-checkpoint-bytes", options.retain_checkpoint_bytes,
                 "while all checkpoint files together exceed this, remove the oldest checkpoints "
                 "of finished jobs (never a queued or running job's; 0 = no budget)")
      ->check(CLI::Range(std::int64_t{0}, std::numeric_limits<std::int64_t>::max()))
      ->capture_default_str();
  app.add_option("--retention-interval-s", options.retention_interval_s,
                 "seconds between two applications of the retention flags (also at start)")
      ->check(CLI::Range(0.1, 1e7))
      ->capture_default_str();
  app.add_option("--shutdown-timeout-s", options.shutdown_timeout_s,
                 "after SIGINT/SIGTERM, seconds to wait for running jobs to stop and checkpoint "
                 "before exiting anyway (status 3; a second signal exits at once)")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  app.add_option("--max-response-bytes", options.max_response_bytes,
                 "largest GetJobFields response sent (larger: RESOURCE_EXHAUSTED with the size)")
      ->check(CLI::Range(std::size_t{4096}, std::size_t{1} << 31))
      ->capture_default_str();
  app.add_option("--rpc-threads", options.rpc_threads,
                 "most gRPC calls served at once (each open WatchJob stream holds one); beyond: "
                 "RESOURCE_EXHAUSTED")
      ->check(CLI::Range(4, 10000))
      ->capture_default_str();
  app.add_option("--max-watch-streams", options.max_watch_streams,
                 "most WatchJob streams open at once (below --rpc-threads); beyond: "
                 "RESOURCE_EXHAUSTED")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  app.add_option("--max-streams-per-connection", options.max_streams_per_connection,
                 "most calls one client connection may have open at once")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  app.add_option("--keepalive-s", options.keepalive_s,
                 "seconds between keepalive pings on an idle connection (a peer that does not "
                 "answer within 10 s is dropped)")
      ->check(CLI::Range(1.0, 86400.0))
      ->capture_default_str();
  app.add_option("--metrics-listen", options.metrics_listen,
                 "HOST:PORT of an HTTP endpoint serving /metrics for Prometheus (off by default; "
                 "port 0 picks a free one, logged)");
  app.add_option("--max-checkpoint-bytes", options.max_checkpoint_bytes,
                 "largest checkpoint state a remote worker may upload (larger: "
                 "RESOURCE_EXHAUSTED, nothing kept)")
      ->check(CLI::Range(std::uint64_t{1024}, seep::service::kDefaultMaxCheckpointUploadBytes))
      ->capture_default_str();
  app.add_option("--executor", options.executor,
                 "who runs the queued jobs besides seepd's --workers and seep-workers started by "
                 "hand: local (nobody else) or slurm (sbatch jobs that start seep-worker; see the "
                 "--slurm-* flags)")
      ->check(CLI::IsMember({"local", "slurm"}))
      ->capture_default_str();
  app.add_option("--slurm-partition", options.slurm.partition,
                 "sbatch --partition of the workers' jobs (default: the cluster's)")
      ->group("Slurm executor");
  app.add_option("--slurm-time", options.slurm.time_limit,
                 "sbatch --time of the workers' jobs, e.g. 2:00:00 (default: the partition's); a "
                 "worker checkpoints and gives its job back --slurm-signal-grace-s before it")
      ->group("Slurm executor");
  app.add_option("--slurm-extra", options.slurm_extra,
                 "more sbatch arguments, separated by spaces (e.g. '--account=geo --qos=long')")
      ->group("Slurm executor");
  app.add_option("--slurm-pack", options.slurm.pack,
                 "0: one Slurm job per seep job; N: Slurm jobs each running N jobs at a time "
                 "until the queue is empty")
      ->check(CLI::Range(0, 256))
      ->capture_default_str()
      ->group("Slurm executor");
  app.add_option("--slurm-max-jobs", options.slurm.max_batch_jobs,
                 "most Slurm jobs of this seepd pending or running at once")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str()
      ->group("Slurm executor");
  app.add_option("--slurm-worker", options.slurm.worker_path,
                 "seep-worker's path on the compute nodes (default: the one beside this seepd)")
      ->group("Slurm executor");
  app.add_option("--slurm-server", options.slurm.server,
                 "the address the workers dial (default: --listen with the bound port, a "
                 "wildcard host replaced by this host's name)")
      ->group("Slurm executor");
  app.add_option(
         "--slurm-worker-args", options.slurm_worker_args,
         "more seep-worker arguments, separated by spaces (e.g. '--tls-ca /etc/seep/ca.pem')")
      ->group("Slurm executor");
  app.add_option("--slurm-output", options.slurm.output,
                 "sbatch --output of the workers' jobs (default: <data-dir>/slurm/"
                 "seep-worker-%j.out; on a cluster without a shared filesystem, a path that exists "
                 "on the nodes)")
      ->group("Slurm executor");
  app.add_option("--slurm-signal-grace-s", options.slurm.signal_grace_s,
                 "sbatch --signal=B:TERM@N: seconds before the time limit at which a worker is "
                 "told to checkpoint and give its job back (also what --requeue preemption gives)")
      ->check(CLI::Range(5, 86400))
      ->capture_default_str()
      ->group("Slurm executor");
  app.add_option("--slurm-poll-s", options.slurm_poll_s,
                 "seconds between two looks at squeue and the queue (a submit or cancel looks at "
                 "once)")
      ->check(CLI::Range(0.2, 3600.0))
      ->capture_default_str()
      ->group("Slurm executor");
  CLI11_PARSE(app, argc, argv);
  if (options.executor != "slurm") {
    for (const CLI::Option* option : app.get_options()) {
      if (option->get_group() == "Slurm executor" && option->count() > 0) {
        std::fprintf(stderr, "seepd: %s needs --executor slurm (the executor is %s)\n",
                     option->get_name().c_str(), options.executor.c_str());
        return 2;
      }
    }
  }
  try {
    return Run(options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "seepd: fatal: %s\n", e.what());
    return 1;
  }
}
