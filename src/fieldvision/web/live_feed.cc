#include "fieldvision/web/live_feed.h"

#include <regex>
#include <variant>

#include <zmq.hpp>

#include "fieldvision/net/endpoint.h"
#include "fieldvision/net/messages.h"
#include "fieldvision/web/workspace.h"

namespace fv::web {

using json = nlohmann::json;

LiveFeed::LiveFeed(EventHub* events)
    : events_(events),
      context_(new zmq::context_t(1), [](void* c) { delete static_cast<zmq::context_t*>(c); }) {}

LiveFeed::~LiveFeed() { Stop(); }

void LiveFeed::Start(const std::string& endpoint) {
  // The host as a name or address only (the page's text reaches ZeroMQ's connect).
  static const std::regex kTcp(
      R"(tcp://[A-Za-z0-9.\-]+:[0-9]{1,5}|tcp://\[[0-9A-Fa-f:]+\]:[0-9]{1,5})");
  const std::string problem = net::EndpointProblem(endpoint, /*bind=*/false);
  if (endpoint.size() > 200 || !problem.empty() || !std::regex_match(endpoint, kTcp)) {
    throw HttpError(
        400, "live endpoint (the fusion node's --publish): " +
                 (problem.empty() ? "'" + endpoint.substr(0, 200) + "' is not tcp://HOST:PORT"
                                  : problem));
  }
  std::lock_guard<std::mutex> control(control_);
  StopLocked();
  auto& ctx = *static_cast<zmq::context_t*>(context_.get());
  // Connect here so that a refused endpoint is an error of the request.
  auto socket = std::make_shared<zmq::socket_t>(ctx, zmq::socket_type::sub);
  try {
    socket->set(zmq::sockopt::linger, 0);
    socket->set(zmq::sockopt::rcvtimeo, 100);
    socket->set(zmq::sockopt::rcvhwm, 1000);
    socket->set(zmq::sockopt::ipv6, 1);
    socket->set(zmq::sockopt::subscribe, "ball");
    socket->connect(endpoint);
  } catch (const zmq::error_t& e) {
    throw HttpError(400, "cannot subscribe to '" + endpoint + "': " + e.what());
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    endpoint_ = endpoint;
    running_ = true;
    received_ = malformed_ = 0;
    last_ = nullptr;
  }
  stop_ = false;
  thread_ = std::thread([this, socket] {
    while (!stop_) {
      zmq::message_t topic;
      zmq::recv_result_t got;
      try {
        got = socket->recv(topic);
      } catch (const zmq::error_t&) {
        break;  // context terminated
      }
      if (!got) continue;  // timeout: check stop_
      if (!topic.more()) {
        std::lock_guard<std::mutex> lock(mutex_);
        ++malformed_;
        continue;
      }
      zmq::message_t payload;
      if (!socket->recv(payload)) continue;
      while (payload.more()) {  // extra frames: not ours
        zmq::message_t extra;
        if (!socket->recv(extra)) break;
      }
      json j;
      try {
        const net::Message m = net::Decode(payload.data(), payload.size());
        const auto* b = std::get_if<net::BallMessage>(&m);
        if (!b) throw net::MessageError(net::MessageError::Reason::kMalformed, "not a ball");
        j = {{"frame", b->frame},   {"time_s", b->time_s},
             {"x_m", b->x_m},       {"y_m", b->y_m},
             {"z_m", b->z_m},       {"n_cams", b->n_cams},
             {"err_px", b->err_px}, {"latency_s", b->latency_s}};
      } catch (const fv::Error&) {
        std::lock_guard<std::mutex> lock(mutex_);
        ++malformed_;
        continue;
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++received_;
        last_ = j;
      }
      if (events_) events_->Publish("ball", j);
    }
  });
  if (events_) events_->Publish("live", {{"state", "running"}, {"endpoint", endpoint}});
}

void LiveFeed::Stop() {
  std::lock_guard<std::mutex> control(control_);
  StopLocked();
}

void LiveFeed::StopLocked() {
  if (!thread_.joinable()) return;
  stop_ = true;
  thread_.join();
  std::string endpoint;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_ = false;
    endpoint = endpoint_;
  }
  if (events_) events_->Publish("live", {{"state", "idle"}, {"endpoint", endpoint}});
}

json LiveFeed::Status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {{"state", running_ ? "running" : "idle"},
          {"endpoint", endpoint_},
          {"received", received_},
          {"malformed", malformed_},
          {"last", last_}};
}

}  // namespace fv::web
