// seep: the command-line client of seepd. It links the generated protocol code only, never the
// physics.
#include <CLI/CLI.hpp>

#include "commands.h"

int main(int argc, char** argv) {
  using namespace seep::client;  // NOLINT(google-build-using-namespace)
  GlobalOptions global;
  CLI::App app{"seep: submit and follow seepage simulations on a seepd server"};
  app.require_subcommand(1);
  app.fallthrough();  // global options may also follow the subcommand: seep result <id> --json
  app.add_option("--server", global.server, "seepd address")
      ->envname("SEEP_SERVER")
      ->capture_default_str();
  app.add_option("--timeout", global.timeout_s, "seconds to wait for each call")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--json", global.json, "print machine-readable JSON");
  app.add_option("--token", global.token,
                 "bearer token for a seepd started with a token (visible in ps: prefer "
                 "SEEP_TOKEN or --token-file)")
      ->envname("SEEP_TOKEN");
  app.add_option("--token-file", global.token_file,
                 "read the bearer token from this file (wins over --token and SEEP_TOKEN)");
  app.add_flag("--tls", global.tls, "connect with TLS, trusting the system's root certificates");
  app.add_option("--tls-ca", global.tls_ca,
                 "connect with TLS, trusting this PEM CA (or self-signed) certificate");

  SubmitOptions submit;
  auto* submit_cmd = app.add_subcommand("submit", "queue a scene file (.textproto or .json)");
  submit_cmd->add_option("scene", submit.scene_file, "scene file")->required();
  submit_cmd->add_option("--name", submit.name, "job name (default: the scene's name)");
  submit_cmd->add_option("--request-id", submit.request_id,
                         "idempotency key: submitting it again returns the same job");
  submit_cmd->add_flag("--watch", submit.watch, "follow the job until it finishes");

  std::string job_id;
  auto* watch_cmd = app.add_subcommand("watch", "follow a job's progress until it finishes");
  watch_cmd->add_option("job", job_id, "job id")->required();
  auto* show_cmd = app.add_subcommand("show", "show a job and its result");
  show_cmd->add_option("job", job_id, "job id")->required();

  ListOptions list;
  auto* list_cmd = app.add_subcommand("list", "list jobs, newest first");
  list_cmd->add_option("--limit", list.limit, "at most this many jobs")
      ->check(CLI::Range(1u, 100000u))
      ->capture_default_str();
  list_cmd->add_option("--state", list.states,
                       "only jobs in this state (queued, running, succeeded, failed, cancelled); "
                       "repeat for several");
  list_cmd->add_option("--name", list.name_contains, "only jobs whose name contains this");
  auto* cancel_cmd = app.add_subcommand("cancel", "cancel a queued or running job");
  cancel_cmd->add_option("job", job_id, "job id")->required();
  auto* resume_cmd =
      app.add_subcommand("resume", "run a failed or cancelled job again (a new attempt)");
  resume_cmd->add_option("job", job_id, "job id")->required();
  auto* result_cmd = app.add_subcommand("result", "show the metrics of a succeeded job");
  result_cmd->add_option("job", job_id, "job id")->required();
  auto* health_cmd = app.add_subcommand("health", "check that seepd is serving");

  CLI11_PARSE(app, argc, argv);
  if (const int bad = LoadCredentials(&global); bad != 0) return bad;
  if (*submit_cmd) return Submit(global, submit);
  if (*watch_cmd) return Watch(global, job_id);
  if (*show_cmd) return Show(global, job_id);
  if (*list_cmd) return List(global, list);
  if (*cancel_cmd) return Cancel(global, job_id);
  if (*resume_cmd) return Resume(global, job_id);
  if (*result_cmd) return Result(global, job_id);
  if (*health_cmd) return Health(global);
  return 2;
}
