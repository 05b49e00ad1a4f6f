// `seep sweep submit|show|plot|cancel|resume|delete`: a family of jobs made from one base scene
// (a seep.v1.Sweep file), followed and tabulated as a whole. Exit codes as in commands.h; `sweep
// submit --watch` exits 20 when a job of the sweep FAILED, else 21 when one was CANCELLED.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"

namespace seep::client {

struct SweepOptions {
  std::string file;  // submit
  std::string request_id;
  int priority = 0;
  std::vector<std::string> labels;  // KEY=VALUE
  bool watch = false;
  std::string sweep_id;              // show, plot, cancel, resume, delete
  std::vector<std::string> metrics;  // show: the metric columns (default: all)
  bool csv = false;                  // show
  std::string x_path;                // plot
  std::string y_metric;              // plot
  std::string out_file;              // plot
  bool log_x = false;                // plot
  bool log_y = false;                // plot
};

// The `sweep` command and its subcommands (options held by pointer: CLI11 keeps addresses).
struct SweepCommands {
  CLI::App* sweep_cmd = nullptr;
  CLI::App* submit_cmd = nullptr;
  CLI::App* show_cmd = nullptr;
  CLI::App* plot_cmd = nullptr;
  CLI::App* cancel_cmd = nullptr;
  CLI::App* resume_cmd = nullptr;
  CLI::App* delete_cmd = nullptr;
  std::shared_ptr<SweepOptions> options;
};

SweepCommands AddSweepCommands(CLI::App& app);
// Runs the chosen subcommand; -1 if `sweep` was not chosen.
int RunSweepCommands(const GlobalOptions& global, const SweepCommands& commands);

}  // namespace seep::client
