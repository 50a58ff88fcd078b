// Live updates for the studio's pages: a hub of numbered events (type + JSON data) that the
// server streams to every open page as Server-Sent Events (text/event-stream, WHATWG HTML
// "Server-sent events"). Pages learn there when a file was saved or a run progressed.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace fv::web {

class EventHub {
 public:
  // Adds an event; waiting readers wake up. Keeps the last `kKeep` events.
  void Publish(const std::string& type, const nlohmann::json& data);
  // Events after `cursor` as SSE text ("id: N\nevent: TYPE\ndata: JSON\n\n"), waiting up to
  // `timeout` for one; advances `cursor`. False once the hub is closed.
  bool Wait(uint64_t& cursor, std::string& out, std::chrono::milliseconds timeout);
  // The number of the last event (a new reader starts there).
  uint64_t Last() const;
  // Wakes and ends every reader (the server stops).
  void Close();

 private:
  static constexpr size_t kKeep = 256;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::pair<uint64_t, std::string>> events_;
  uint64_t last_ = 0;
  bool closed_ = false;
};

}  // namespace fv::web
