// `fieldvision studio`: an HTTP server (cpp-httplib) that serves the built front end (studio/,
// TypeScript + Vite) and the JSON API (studio_api.h) over the working folder, with live updates
// as Server-Sent Events at /api/events. It binds the loopback address unless told otherwise;
// on any other address every /api request needs the session token (header X-Studio-Token or
// ?token=), printed in the URL at start.
#pragma once

#include <iosfwd>
#include <memory>
#include <string>

#include "fieldvision/web/events.h"

namespace fv::web {

struct StudioOptions {
  std::string host = "127.0.0.1";  // address to bind; not loopback -> token required
  int port = 8470;                 // 0: any free port
  std::string root;                // working folder; empty: the current folder
  std::string assets;              // built front end (index.html); empty: studio/dist or installed
  std::string token;               // for a non-loopback host; empty: a random one
  std::string program;             // the fieldvision executable jobs run; empty: this program
  // A fusion node's PUB address (fuse --publish) the 3D view's live mode subscribes to from the
  // start, tcp://HOST:PORT; empty: none until a page starts one.
  std::string live;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

// True for the IPv4 literals 127.0.0.0/8, ::1 and localhost (not other names beginning "127.").
bool IsLoopback(const std::string& host);

class StudioServer {
 public:
  // Throws fv::Error for bad options or a working folder that does not exist.
  explicit StudioServer(const StudioOptions& options);
  ~StudioServer();
  StudioServer(const StudioServer&) = delete;
  StudioServer& operator=(const StudioServer&) = delete;

  // Binds and serves on a background thread; returns the port. Throws fv::Error naming the
  // address when it cannot bind.
  int Start();
  // Ends open event streams and stops serving (also done by the destructor).
  void Stop();

  int port() const;
  // The address to open, with ?token=... when a token is required.
  std::string Url() const;
  bool token_required() const;
  const std::string& token() const;
  // Whether the front end's index.html was found, and where it was looked for.
  bool assets_built() const;
  const std::string& assets_dir() const;
  EventHub& events();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Runs the studio until SIGINT or SIGTERM, printing the address (and what is missing when the
// front end is not built) to `out`. Returns 0.
int RunStudio(const StudioOptions& options, std::ostream& out);

}  // namespace fv::web
