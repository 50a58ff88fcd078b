// Newline-delimited messages over TCP (JSON Lines between camera nodes and the fusion node).
// The server multiplexes any number of node connections with poll(2) in the caller's thread;
// lines longer than a limit are dropped and counted, never buffered without bound; a peer that
// disconnects mid-line loses only that partial line. POSIX sockets: no dependency the project
// does not already have for this small job.
#pragma once

#include <chrono>
#include <cstddef>
#include <deque>
#include <map>
#include <optional>
#include <string>

namespace fv {

struct LineServerOptions {
  std::string bind_address = "127.0.0.1";  // "0.0.0.0" to accept nodes on other machines
  int port = 0;                            // 0: any free port (see LineServer::port())
  size_t max_line_bytes = 1 << 20;         // longer lines are dropped
  int max_clients = 64;
  void Check() const;
};

struct ReceivedLine {
  int client = 0;  // connection number, from 0 in order of connection
  std::string line;
};

struct LineServerStats {
  int clients_connected = 0;  // ever
  int clients_open = 0;
  long long lines = 0;
  long long lines_too_long = 0;
  long long partial_lines_lost = 0;  // peers that closed in the middle of a line
};

class LineServer {
 public:
  // Binds and listens; throws fv::Error naming the address and port on failure.
  explicit LineServer(const LineServerOptions& options);
  ~LineServer();
  LineServer(const LineServer&) = delete;
  LineServer& operator=(const LineServer&) = delete;

  int port() const { return port_; }
  // The next complete line from any client, waiting up to `timeout`; nullopt on timeout.
  std::optional<ReceivedLine> Next(std::chrono::milliseconds timeout);
  const LineServerStats& stats() const { return stats_; }

 private:
  void Poll(std::chrono::milliseconds timeout);
  void ReadFrom(int fd);
  LineServerOptions options_;
  int listen_fd_ = -1;
  int port_ = 0;
  struct Client {
    int id = 0;
    std::string buffer;
    bool discarding = false;  // inside an over-long line
  };
  std::map<int, Client> clients_;  // by fd
  std::deque<ReceivedLine> ready_;
  LineServerStats stats_;
};

class LineClient {
 public:
  // Connects, retrying until `timeout`; throws fv::Error naming host:port when it cannot.
  LineClient(const std::string& host, int port,
             std::chrono::milliseconds timeout = std::chrono::milliseconds(5000));
  ~LineClient();
  LineClient(const LineClient&) = delete;
  LineClient& operator=(const LineClient&) = delete;
  // Sends `line` plus '\n'; a line must not contain '\n'. Throws fv::Error if the peer is gone.
  void Send(const std::string& line);
  void Close();

 private:
  std::string peer_;
  int fd_ = -1;
};

// "host:port" -> (host, port); throws fv::Error naming `text` when malformed.
std::pair<std::string, int> ParseHostPort(const std::string& text);

}  // namespace fv
