// seep: the command-line client of seepd. It links the generated protocol code only, never the
// physics.
#include <CLI/CLI.hpp>

#include "calibration_commands.h"
#include "commands.h"
#include "field_commands.h"
#include "job_admin_commands.h"
#include "sweep_commands.h"

namespace {

// The options of a new job, which submit and fork share.
void AddJobOptions(CLI::App* command, seep::client::SubmitOptions* options) {
  command->add_option("--name", options->name, "job name (default: the scene's name)");
  command->add_option("--request-id", options->request_id,
                      "idempotency key: submitting it again returns the same job");
  command->add_option("--priority", options->priority,
                      "queued jobs run highest priority first (-1000 to 1000; default 0)");
  command->add_option("--label", options->labels,
                      "a KEY=VALUE label to find the job by (seep list --label); repeatable");
  command->add_flag("--watch", options->watch, "follow the job until it finishes");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace seep::client;  // NOLINT(google-build-using-namespace)
  GlobalOptions global;
  CLI::App app{"seep: submit and follow seepage simulations on a seepd server"};
  app.require_subcommand(1);
  app.footer(kExitCodeHelp);
  app.fallthrough();  // global options may also follow the subcommand: seep result <id> --json
  app.add_option("--server", global.server, "seepd address")
      ->envname("SEEP_SERVER")
      ->capture_default_str();
  app.add_option("--timeout", global.timeout_s, "seconds to wait for each call")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag(
      "--json", global.json,
      "print machine-readable JSON on stdout (submit, fork, show, list, result, watch, cancel, "
      "resume, delete, events, health, calibrate, calibrations, sweep)");
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
  AddJobOptions(submit_cmd, &submit);

  SubmitOptions fork;
  std::uint64_t fork_step = 0;
  auto* fork_cmd = app.add_subcommand(
      "fork", "queue a scene file that continues a staged job from one of its checkpoints");
  fork_cmd->add_option("job", fork.from_job_id, "the job to branch from")->required();
  fork_cmd
      ->add_option("scene", fork.scene_file,
                   "scene file: the job's scene with new stages after its current one")
      ->required();
  auto* fork_step_opt = fork_cmd->add_option(
      "--step", fork_step, "the checkpoint step to start from (default: the job's newest)");
  AddJobOptions(fork_cmd, &fork);

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
  list_cmd->add_option("--kind", list.kinds,
                       "only jobs of this kind (simulation, calibration); repeat for several");
  list_cmd->add_option("--label", list.labels,
                       "only jobs carrying this KEY=VALUE label; repeat: all must be present");
  auto* cancel_cmd = app.add_subcommand("cancel", "cancel a queued or running job");
  cancel_cmd->add_option("job", job_id, "job id")->required();
  auto* resume_cmd =
      app.add_subcommand("resume", "run a failed or cancelled job again (a new attempt)");
  resume_cmd->add_option("job", job_id, "job id")->required();
  auto* result_cmd = app.add_subcommand("result", "show the metrics of a succeeded job");
  result_cmd->add_option("job", job_id, "job id")->required();
  auto* health_cmd = app.add_subcommand("health", "check that seepd is serving");
  auto* delete_cmd =
      app.add_subcommand("delete", "delete a finished job with its result and checkpoint files");
  delete_cmd->add_option("job", job_id, "job id")->required();
  auto* events_cmd = app.add_subcommand(
      "events", "a job's history: claims, resumes, checkpoints, interruptions, outcome");
  events_cmd->add_option("job", job_id, "job id")->required();

  CalibrateOptions calibrate;
  auto* calibrate_cmd = app.add_subcommand(
      "calibrate", "queue a residual-aperture calibration (a seep.v1.Calibration file)");
  calibrate_cmd->add_option("file", calibrate.file, "calibration file (.textproto or .json)")
      ->required();
  calibrate_cmd->add_option("--tag", calibrate.tags, "a tag stored with the records; repeatable");
  calibrate_cmd->add_option("--label", calibrate.labels,
                            "a KEY=VALUE label of the job (seep list --label); repeatable");
  calibrate_cmd->add_option("--name", calibrate.name, "job name (default: the file's name)");
  calibrate_cmd->add_option("--from-job", calibrate.from_job,
                            "take the packing of this earlier job (overrides from_job_id)");
  calibrate_cmd->add_option("--request-id", calibrate.request_id,
                            "idempotency key: submitting it again returns the same job");
  calibrate_cmd->add_flag("--watch", calibrate.watch, "follow the job until it finishes");

  CalibrationListOptions calibrations;
  auto* calibrations_cmd =
      app.add_subcommand("calibrations", "list stored calibration records, newest first");
  calibrations_cmd->add_option("--k-min", calibrations.k_min, "least target permeability, m^2");
  calibrations_cmd->add_option("--k-max", calibrations.k_max, "largest target permeability, m^2");
  calibrations_cmd->add_option("--porosity-min", calibrations.porosity_min, "least 2D porosity");
  calibrations_cmd->add_option("--porosity-max", calibrations.porosity_max, "largest 2D porosity");
  calibrations_cmd->add_option("--radius-min", calibrations.radius_min, "least mean radius, m");
  calibrations_cmd->add_option("--radius-max", calibrations.radius_max, "largest mean radius, m");
  calibrations_cmd->add_option("--tag", calibrations.tags,
                               "only records carrying this tag; repeat: all must be present");
  calibrations_cmd->add_option("--after", calibrations.after,
                               "created at or after this RFC 3339 time");
  calibrations_cmd->add_option("--before", calibrations.before, "created before this time");
  calibrations_cmd->add_option("--job", calibrations.job, "only this job's records");
  calibrations_cmd->add_option("--limit", calibrations.limit, "at most this many records")
      ->check(CLI::Range(1u, 100000u))
      ->capture_default_str();
  calibrations_cmd->add_flag("--csv", calibrations.csv, "print CSV (every field, full precision)");
  CalibrationLookupOptions lookup;
  auto* lookup_cmd = calibrations_cmd->add_subcommand(
      "lookup", "the stored calibrations nearest to a packing and k, and an interpolated a0");
  lookup_cmd->add_option("--porosity", lookup.porosity, "2D porosity of the packing")->required();
  lookup_cmd->add_option("--mean-radius", lookup.mean_radius_m, "mean particle radius, m")
      ->required();
  lookup_cmd->add_option("--k", lookup.permeability_m2, "target permeability, m^2")->required();
  lookup_cmd->add_option("--particles", lookup.particles, "particle count (optional)");
  lookup_cmd->add_option("--coordination", lookup.coordination, "coordination number (optional)");
  lookup_cmd->add_option("--limit", lookup.limit, "neighbours to print")
      ->check(CLI::Range(1u, 100u))
      ->capture_default_str();

  const FieldCommands field_commands = AddFieldCommands(app);
  const SweepCommands sweep_commands = AddSweepCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; a wrong command line gets one code scripts can tell apart
    // from the gRPC codes (CLI11's own codes vary by error kind).
    const int printed = app.exit(e);
    return printed == 0 ? 0 : kExitUsage;
  }
  if (const int bad = LoadCredentials(&global); bad != 0) return bad;
  if (const int rc = RunFieldCommands(global, field_commands); rc >= 0) return rc;
  if (const int rc = RunSweepCommands(global, sweep_commands); rc >= 0) return rc;
  if (*submit_cmd) return Submit(global, submit);
  if (*fork_cmd) {
    if (fork_step_opt->count() > 0) fork.from_step = fork_step;
    return Submit(global, fork);
  }
  if (*watch_cmd) return Watch(global, job_id);
  if (*show_cmd) return Show(global, job_id);
  if (*list_cmd) return List(global, list);
  if (*cancel_cmd) return Cancel(global, job_id);
  if (*resume_cmd) return Resume(global, job_id);
  if (*result_cmd) return Result(global, job_id);
  if (*health_cmd) return Health(global);
  if (*delete_cmd) return Delete(global, job_id);
  if (*events_cmd) return Events(global, job_id);
  if (*calibrate_cmd) return Calibrate(global, calibrate);
  if (*lookup_cmd) return LookupCalibration(global, lookup);
  if (*calibrations_cmd) return ListCalibrations(global, calibrations);
  return 2;
}
