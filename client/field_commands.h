// `seep export` (a job's fields as VTK or CSV files, and its time series as CSV) and `seep plot`
// (an SVG of the pressure profile against the analytic solution, of time series columns, or a
// picture of the particles, bonds, walls and domain pressure at a checkpoint).
// Both read the fields through GetJobFields, so the CLI still links no physics.
//
// Exit codes as in commands.h, plus kExitWriteFailed when an output file cannot be written.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"

namespace seep::client {

inline constexpr int kExitWriteFailed = 73;  // EX_CANTCREAT of sysexits.h

struct ExportOptions {
  std::string job_id;
  std::string out_dir;
  std::uint64_t step = 0;  // 0 = the newest checkpoint (a finished job's final state)
  bool all_steps = false;
  std::string format = "vtk";  // vtk or csv
};

struct PlotOptions {
  std::string job_id;
  std::string out_file;              // empty: <job>-<what>.svg in the working directory
  std::string what = "profile";      // profile, series or particles
  std::vector<std::string> columns;  // series: these columns (default: all but time_s)
  std::uint64_t step = 0;            // profile, particles: this checkpoint (0 = newest)
};

// The two subcommands and the options CLI11 fills (held by pointer: CLI11 keeps their addresses).
struct FieldCommands {
  CLI::App* export_cmd = nullptr;
  CLI::App* plot_cmd = nullptr;
  std::shared_ptr<ExportOptions> export_options;
  std::shared_ptr<PlotOptions> plot_options;
};

FieldCommands AddFieldCommands(CLI::App& app);
// Runs the chosen one; -1 if neither was chosen.
int RunFieldCommands(const GlobalOptions& global, const FieldCommands& commands);

int Export(const GlobalOptions& global, const ExportOptions& options);
int Plot(const GlobalOptions& global, const PlotOptions& options);

}  // namespace seep::client
