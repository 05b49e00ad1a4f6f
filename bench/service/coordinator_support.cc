// seepd as a child process and the sweeps both parts of seep_coordinator_bench submit
// (coordinator_bench.h).
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "coordinator_bench.h"

namespace seep::bench {

Seepd::Seepd(const CoordinatorOptions& options, const std::string& name,
             const std::vector<std::string>& extra)
    : output_(options.dir / (name + ".out")) {
  const std::filesystem::path port_file = options.dir / (name + ".port");
  std::vector<std::string> argv = {
      options.seepd, "--listen",        "127.0.0.1:0", "--data-dir", (options.dir / name).string(),
      "--port-file", port_file.string()};
  // A pure coordinator unless `extra` gives seepd workers of its own.
  if (std::find(extra.begin(), extra.end(), "--workers") == extra.end()) {
    argv.insert(argv.end(), {"--workers", "0"});
  }
  argv.insert(argv.end(), extra.begin(), extra.end());
  process_ = ChildProcess(argv, output_);
  port_ = process_.started() ? WaitForPortFile(port_file) : -1;
  if (port_ <= 0) {
    std::printf("seepd (%s) did not start; see %s\n", options.seepd.c_str(), output_.c_str());
  }
}

std::shared_ptr<grpc::Channel> Seepd::Channel(int tag) const {
  grpc::ChannelArguments args;
  args.SetInt("seep.bench.channel", tag);  // a distinct argument: a connection of its own
  args.SetMaxReceiveMessageSize(128 << 20);
  return grpc::CreateCustomChannel(address(), grpc::InsecureChannelCredentials(), args);
}

bool Seepd::Stop() { return ExitedCleanly(process_.Stop(SIGTERM)); }

v1::Sweep InletPressureSweep(const v1::Scene& base, int jobs) {
  v1::Sweep sweep;
  sweep.set_name(base.name());
  sweep.set_combine(v1::SWEEP_COMBINE_PRODUCT);
  *sweep.mutable_scene() = base;
  v1::SweepAxis* axis = sweep.add_axes();
  axis->set_path("boundary.inlet_pressure_pa");
  for (int i = 0; i < jobs; ++i) axis->add_numbers(1e5 + 10.0 * i);
  return sweep;
}

std::optional<v1::SweepStatus> SubmitSweep(v1::SeepService::Stub& stub, const v1::Sweep& sweep) {
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::minutes(5));
  v1::SubmitSweepRequest request;
  *request.mutable_sweep() = sweep;
  v1::SubmitSweepResponse response;
  const grpc::Status status = stub.SubmitSweep(&ctx, request, &response);
  if (!status.ok()) {
    std::printf("SubmitSweep failed: %d %s\n", status.error_code(), status.error_message().c_str());
    return std::nullopt;
  }
  return response.sweep();
}

}  // namespace seep::bench
