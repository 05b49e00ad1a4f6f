// MetricsEndpoint: seepd's optional HTTP endpoint for Prometheus (--metrics-listen HOST:PORT).
// GET /metrics answers with the text exposition format that `render` makes at each scrape; any
// other path is 404. cpp-httplib serves it on its own threads, apart from the gRPC server.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "seep/core/status.h"

namespace httplib {
class Server;
}

namespace seep::service {

class MetricsEndpoint {
 public:
  explicit MetricsEndpoint(std::function<std::string()> render);
  ~MetricsEndpoint();
  MetricsEndpoint(const MetricsEndpoint&) = delete;
  MetricsEndpoint& operator=(const MetricsEndpoint&) = delete;

  // Binds HOST:PORT (port 0 picks a free one) and serves; INVALID_ARGUMENT naming --metrics-listen
  // for an address without a port, UNAVAILABLE when it cannot be bound.
  core::Status Start(const std::string& listen);
  // The bound port (after Start).
  int port() const { return port_; }
  void Stop();

 private:
  std::function<std::string()> render_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
};

}  // namespace seep::service
