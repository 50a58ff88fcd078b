#include "fieldvision/web/events.h"

namespace fv::web {

void EventHub::Publish(const std::string& type, const nlohmann::json& data) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++last_;
    events_.emplace_back(
        last_, "id: " + std::to_string(last_) + "\nevent: " + type + "\ndata: " +
                   data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n\n");
    while (events_.size() > kKeep) events_.pop_front();
  }
  changed_.notify_all();
}

bool EventHub::Wait(uint64_t& cursor, std::string& out, std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return closed_ || last_ > cursor; });
  if (closed_) return false;
  for (const auto& [id, text] : events_) {
    if (id > cursor) out += text;
  }
  cursor = last_;
  return true;
}

uint64_t EventHub::Last() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_;
}

void EventHub::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

}  // namespace fv::web
