// The floor under part 1's CPU figure: what seepd spends on gRPC alone at the same call rate.
// The same number of client threads, each with its own channel, call grpc.health.v1.Health/Check
// (no store, no lock, an answer from memory) at the rate the simulated workers made their calls;
// seepd's CPU over that stretch is what any handler pays before doing its own work.
#include <chrono>
#include <thread>
#include <vector>

#include "coordinator_bench.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "service_bench.h"

namespace seep::bench {

double TrivialCallCpuPercent(Seepd& seepd, int clients, double calls_per_second, double seconds) {
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(clients / calls_per_second));
  const auto start = Clock::now() + std::chrono::milliseconds(500);  // channels connect first
  const auto end =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::vector<std::jthread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      auto stub = grpc::health::v1::Health::NewStub(seepd.Channel(1000 + c));
      // Spread over one period, as the workers' calls were.
      for (auto next = start + period * c / clients; next < end; next += period) {
        std::this_thread::sleep_until(next);
        grpc::ClientContext ctx;
        ctx.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
        grpc::health::v1::HealthCheckRequest request;
        grpc::health::v1::HealthCheckResponse response;
        (void)stub->Check(&ctx, request, &response);
      }
    });
  }
  std::this_thread::sleep_until(start);
  const double cpu_start = seepd.process().CpuSeconds();
  std::this_thread::sleep_until(end);
  const double cpu_end = seepd.process().CpuSeconds();
  threads.clear();
  return 100.0 * (cpu_end - cpu_start) / seconds;
}

}  // namespace seep::bench
