// Live ball positions for the studio's 3D view: a ZeroMQ SUB socket connected to a fusion node's
// PUB address (`fuse --publish`, topic "ball", net/messages.h), each decoded position republished
// on the studio's event hub as a "ball" event (streamed to the pages as Server-Sent Events), and
// the feed's state as "live" events. Malformed messages are counted and skipped.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "fieldvision/web/events.h"

namespace fv::web {

class LiveFeed {
 public:
  // `events` must outlive the feed.
  explicit LiveFeed(EventHub* events);
  ~LiveFeed();  // stops the subscription
  LiveFeed(const LiveFeed&) = delete;
  LiveFeed& operator=(const LiveFeed&) = delete;

  // Subscribes to `endpoint` (tcp://HOST:PORT), replacing a running subscription. ZeroMQ
  // reconnects by itself, so a fusion node may start later. Throws HttpError 400 for an endpoint
  // that is not tcp://HOST:PORT or that ZeroMQ refuses.
  void Start(const std::string& endpoint);
  void Stop();
  // {state: "idle"|"running", endpoint, received, malformed, last (the last position or null)}.
  nlohmann::json Status() const;

 private:
  void StopLocked();

  EventHub* events_;
  std::mutex control_;  // Start and Stop, one at a time
  std::unique_ptr<void, void (*)(void*)> context_;
  mutable std::mutex mutex_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::string endpoint_;
  bool running_ = false;
  long long received_ = 0, malformed_ = 0;
  nlohmann::json last_;
};

}  // namespace fv::web
