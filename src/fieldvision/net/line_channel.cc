#include "fieldvision/net/line_channel.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <thread>
#include <vector>

#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv {

void LineServerOptions::Check() const {
  CheckInRange(port, 0, 65535, "LineServerOptions.port");
  FV_REQUIRE(max_line_bytes >= 16, "LineServerOptions.max_line_bytes must be >= 16");
  FV_REQUIRE(max_clients >= 1, "LineServerOptions.max_clients must be >= 1");
}

LineServer::LineServer(const LineServerOptions& options) : options_(options) {
  options_.Check();
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  FV_REQUIRE(listen_fd_ >= 0, "cannot create a socket: {}", std::strerror(errno));
  const int one = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(options_.port));
  if (::inet_pton(AF_INET, options_.bind_address.c_str(), &addr.sin_addr) != 1) {
    ::close(listen_fd_);
    Throw("listen address '{}' is not an IPv4 address", options_.bind_address);
  }
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      ::listen(listen_fd_, 16) != 0) {
    const std::string why = std::strerror(errno);
    ::close(listen_fd_);
    Throw("cannot listen on {}:{}: {}", options_.bind_address, options_.port, why);
  }
  socklen_t len = sizeof(addr);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
}

LineServer::~LineServer() {
  for (const auto& [fd, client] : clients_) ::close(fd);
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

void LineServer::ReadFrom(int fd) {
  Client& c = clients_[fd];
  char buf[65536];
  const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
  if (n <= 0) {
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return;
    if (!c.buffer.empty() || c.discarding) ++stats_.partial_lines_lost;
    ::close(fd);
    clients_.erase(fd);
    --stats_.clients_open;
    return;
  }
  for (ssize_t i = 0; i < n; ++i) {
    const char ch = buf[i];
    if (ch == '\n') {
      if (c.discarding) {
        c.discarding = false;
      } else {
        if (!c.buffer.empty() && c.buffer.back() == '\r') c.buffer.pop_back();
        ready_.push_back({c.id, std::move(c.buffer)});
        ++stats_.lines;
      }
      c.buffer.clear();
    } else if (!c.discarding) {
      c.buffer.push_back(ch);
      if (c.buffer.size() > options_.max_line_bytes) {
        c.buffer.clear();
        c.discarding = true;
        ++stats_.lines_too_long;
      }
    }
  }
}

void LineServer::Poll(std::chrono::milliseconds timeout) {
  std::vector<pollfd> fds;
  fds.push_back({listen_fd_, POLLIN, 0});
  for (const auto& [fd, client] : clients_) fds.push_back({fd, POLLIN, 0});
  const int r = ::poll(fds.data(), fds.size(), static_cast<int>(timeout.count()));
  if (r <= 0) return;
  for (size_t i = 1; i < fds.size(); ++i) {
    if (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) ReadFrom(fds[i].fd);
  }
  if (fds[0].revents & POLLIN) {
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd >= 0) {
      if (static_cast<int>(clients_.size()) >= options_.max_clients) {
        ::close(fd);
      } else {
        clients_[fd].id = stats_.clients_connected++;
        ++stats_.clients_open;
      }
    }
  }
}

std::optional<ReceivedLine> LineServer::Next(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (ready_.empty()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() < 0) return std::nullopt;
    Poll(left);
    if (std::chrono::steady_clock::now() >= deadline && ready_.empty()) return std::nullopt;
  }
  ReceivedLine out = std::move(ready_.front());
  ready_.pop_front();
  return out;
}

std::pair<std::string, int> ParseHostPort(const std::string& text) {
  const size_t colon = text.rfind(':');
  FV_REQUIRE(colon != std::string::npos && colon > 0 && colon + 1 < text.size(),
             "'{}' is not host:port", text);
  const long long port = ParseInt(text.substr(colon + 1), "port in '" + text + "'");
  FV_REQUIRE(port > 0 && port < 65536, "port in '{}' must be 1..65535", text);
  return {text.substr(0, colon), static_cast<int>(port)};
}

LineClient::LineClient(const std::string& host, int port, std::chrono::milliseconds timeout)
    : peer_(host + ":" + std::to_string(port)) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* res = nullptr;
  const int gai = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &res);
  FV_REQUIRE(gai == 0 && res != nullptr, "cannot resolve '{}': {}", peer_, ::gai_strerror(gai));
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::string why;
  while (true) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ >= 0 && ::connect(fd_, res->ai_addr, res->ai_addrlen) == 0) break;
    why = std::strerror(errno);
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    if (std::chrono::steady_clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ::freeaddrinfo(res);
  FV_REQUIRE(fd_ >= 0, "cannot connect to fusion node {}: {}", peer_, why);
  const int one = 1;
  ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
}

LineClient::~LineClient() { Close(); }

void LineClient::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void LineClient::Send(const std::string& line) {
  FV_REQUIRE(fd_ >= 0, "connection to {} is closed", peer_);
  FV_REQUIRE(line.find('\n') == std::string::npos, "a message to {} contains a newline", peer_);
  std::string data = line + '\n';
  size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::send(fd_, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    FV_REQUIRE(n > 0, "connection to {} lost: {}", peer_, std::strerror(errno));
    sent += static_cast<size_t>(n);
  }
}

}  // namespace fv
