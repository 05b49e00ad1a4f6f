#include "metrics/metrics_endpoint.h"

#include <fmt/format.h>
#include <httplib.h>

namespace seep::service {

MetricsEndpoint::MetricsEndpoint(std::function<std::string()> render)
    : render_(std::move(render)) {}

MetricsEndpoint::~MetricsEndpoint() { Stop(); }

core::Status MetricsEndpoint::Start(const std::string& listen) {
  const auto colon = listen.rfind(':');
  if (colon == std::string::npos || colon + 1 == listen.size()) {
    return core::InvalidArgument(
        fmt::format("--metrics-listen: '{}' is not HOST:PORT (e.g. 127.0.0.1:9464)", listen));
  }
  std::string host = listen.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  int port = 0;
  try {
    std::size_t used = 0;
    port = std::stoi(listen.substr(colon + 1), &used);
    if (used != listen.size() - colon - 1 || port < 0 || port > 65535) throw std::out_of_range("");
  } catch (const std::exception&) {
    return core::InvalidArgument(
        fmt::format("--metrics-listen: '{}' has no port number in 0..65535", listen));
  }
  server_ = std::make_unique<httplib::Server>();
  server_->Get("/metrics", [this](const httplib::Request&, httplib::Response& response) {
    response.set_content(render_(), "text/plain; version=0.0.4; charset=utf-8");
  });
  port_ =
      port == 0 ? server_->bind_to_any_port(host) : (server_->bind_to_port(host, port) ? port : -1);
  if (port_ <= 0) {
    server_.reset();
    return core::Unavailable(fmt::format("--metrics-listen: cannot listen on {}", listen));
  }
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  return core::Status::Ok();
}

void MetricsEndpoint::Stop() {
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
  server_.reset();
}

}  // namespace seep::service
