#include "fieldvision/web/studio_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <memory>
#include <ostream>
#include <random>
#include <thread>

#include <fmt/format.h>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/program_paths.h"
#include "fieldvision/util/strings.h"
#include "fieldvision/web/studio_api.h"

#ifndef FV_STUDIO_DIST
#define FV_STUDIO_DIST "studio/dist"
#endif

namespace fv::web {

namespace fs = std::filesystem;

void StudioOptions::Check() const {
  FV_REQUIRE(!host.empty(), "studio: --host is empty");
  FV_REQUIRE(port >= 0 && port <= 65535, "studio: --port must be 0..65535 (got {})", port);
  FV_REQUIRE(live.empty() || live.rfind("tcp://", 0) == 0,
             "studio: --live must be tcp://HOST:PORT (the fusion node's --publish), got '{}'",
             live);
  FV_REQUIRE(token.find_first_of(" \r\n&?#") == std::string::npos,
             "studio: --token must not contain spaces or URL separators");
}

bool IsLoopback(const std::string& host) {
  if (host == "localhost" || host == "::1") return true;
  // A dotted IPv4 literal in 127/8 only: a name such as 127.attacker.example can resolve to
  // anything (DNS rebinding).
  in_addr address{};
  return inet_pton(AF_INET, host.c_str(), &address) == 1 && (ntohl(address.s_addr) >> 24) == 127;
}

namespace {

// Longest life of one event stream, seconds (see /api/events).
constexpr int kStreamS = 60;
// Server threads, and how many of them event streams may hold at once: the rest answer requests
// (16 streams held every thread, and the pages' requests waited until a stream ended).
constexpr int kThreads = 16;
constexpr int kMaxStreams = 8;

// The front end as built in the source tree, else as installed (share/fieldvision/studio).
fs::path DefaultAssetsDir() {
  fs::path built(FV_STUDIO_DIST);
  std::error_code ec;
  if (fs::is_regular_file(built / "index.html", ec)) return built;
  const fs::path installed = util::InstalledDataDir() / "studio";
  return fs::is_regular_file(installed / "index.html", ec) ? installed : built;
}

std::string RandomToken() {
  std::random_device rd;
  std::string t;
  for (int i = 0; i < 4; ++i) t += fmt::format("{:08x}", rd());
  return t;
}

// "host:port", "[::1]:port" or "host" -> the host name.
std::string HostName(const std::string& host_header) {
  if (host_header.empty()) return "localhost";
  if (host_header[0] == '[') return host_header.substr(1, host_header.find(']') - 1);
  return host_header.substr(0, host_header.find(':'));
}

std::string NotBuiltPage(const std::string& assets) {
  return fmt::format(
      R"(<!doctype html><html><head><meta charset="utf-8"><title>fieldvision studio</title></head>
<body style="font-family:sans-serif;max-width:50em;margin:3em auto">
<h1>fieldvision studio: the front end is not built</h1>
<p id="not-built">Missing: <code>{}/index.html</code>. The studio's pages are TypeScript built with
Vite, which needs Node.js and npm (installed by <code>scripts/install-deps.sh</code>). Build them
with <code>make build</code> (or <code>bash studio/build.sh</code>), then reload this page.</p>
<p>The JSON API works without them: <a href="/api/endpoints">/api/endpoints</a>.</p>
</body></html>)",
      assets);
}

}  // namespace

struct StudioServer::Impl {
  StudioOptions options;
  std::unique_ptr<Workspace> workspace;
  EventHub events;
  std::unique_ptr<LiveFeed> live;
  std::unique_ptr<JobRunner> jobs;
  std::unique_ptr<StudioApi> api;
  httplib::Server server;
  std::thread thread;
  std::atomic<bool> loop_ended{false};
  std::shared_ptr<std::atomic<int>> streams = std::make_shared<std::atomic<int>>(0);
  int port = -1;
  bool token_required = false;
  bool assets_built = false;

  bool Authorized(const httplib::Request& req) const {
    if (!token_required) return true;
    if (req.get_header_value("X-Studio-Token") == options.token) return true;
    return req.has_param("token") && req.get_param_value("token") == options.token;
  }

  static void Send(httplib::Response& res, const ApiResponse& r) {
    res.status = r.status;
    res.set_content(r.body, r.content_type);
    res.set_header("Cache-Control", "no-store");
  }

  // Answers the request itself when it may not call: a missing or wrong token, or, without a
  // token, a page not served from a loopback name (DNS rebinding).
  bool Refused(const httplib::Request& req, httplib::Response& res) const {
    if (!Authorized(req)) {
      Send(res,
           {401, "application/json",
            R"j({"error":"missing or wrong studio token (X-Studio-Token header or ?token=)"})j"});
      return true;
    }
    if (token_required || IsLoopback(HostName(req.get_header_value("Host")))) return false;
    Send(res, {403, "application/json",
               R"j({"error":"requests must name a loopback host (Host header)"})j"});
    return true;
  }

  // The event stream, first: the generic /api handler would take it otherwise. A stream ends
  // after kStreamS (the browser reconnects after `retry`, naming the last event it had, and
  // misses nothing the hub still keeps): a tab left open never holds a server thread for good.
  void AddEventStream() {
    server.Get("/api/events", [this](const httplib::Request& req, httplib::Response& res) {
      if (Refused(req, res)) return;
      if (streams->fetch_add(1) >= kMaxStreams) {
        streams->fetch_sub(1);
        return Send(res,
                    {503, "application/json",
                     fmt::format(R"j({{"error":"{} event streams are open (studio tabs): close )j"
                                 R"j(one and reload"}})j",
                                 kMaxStreams)});
      }
      // Held until the response (and its provider) is destroyed: the stream's end.
      auto slot = std::shared_ptr<void>(nullptr, [count = streams](void*) { count->fetch_sub(1); });
      auto cursor = std::make_shared<uint64_t>(events.Last());
      // Resume after the last event the client had (EventSource's reconnect, or ?since=).
      const std::string since = req.has_header("Last-Event-ID")
                                    ? req.get_header_value("Last-Event-ID")
                                    : req.get_param_value("since");
      if (!since.empty() && since.size() < 20 &&
          since.find_first_not_of("0123456789") == std::string::npos) {
        *cursor = std::min<uint64_t>(*cursor, std::stoull(since));
      }
      auto first = std::make_shared<bool>(true);
      const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(kStreamS);
      res.set_header("Cache-Control", "no-store");
      res.set_chunked_content_provider(
          "text/event-stream", [this, cursor, first, end, slot](size_t, httplib::DataSink& sink) {
            std::string out;
            if (*first) {
              *first = false;
              out = "retry: 2000\nevent: hello\ndata: {}\n\n";
            } else if (std::chrono::steady_clock::now() > end ||
                       !events.Wait(*cursor, out, std::chrono::seconds(10))) {
              sink.done();
              return false;
            }
            if (out.empty()) out = ": keep-alive\n\n";
            return sink.write(out.data(), out.size());
          });
    });
  }

  // GET and POST /api/...; other methods get one line saying which are served (httplib
  // answered an empty 400).
  void AddApi() {
    const auto handle = [this](const httplib::Request& req, httplib::Response& res) {
      if (Refused(req, res)) return;
      // A POST must be JSON, which a page of another origin cannot send without asking (CORS).
      if (req.method == "POST" &&
          req.get_header_value("Content-Type").rfind("application/json", 0) != 0) {
        return Send(res, {415, "application/json",
                          R"j({"error":"POST bodies must be sent as application/json"})j"});
      }
      ApiRequest r{req.method, req.path, {}, req.body};
      for (const auto& [k, v] : req.params) r.params[k] = v;
      Send(res, api->Handle(r));
    };
    server.Get(R"(/api/.*)", handle);
    server.Post(R"(/api/.*)", handle);
    const auto other_method = [](const httplib::Request&, httplib::Response& res) {
      Send(res, {405, "application/json",
                 R"j({"error":"method not allowed: the studio's API takes GET and POST"})j"});
    };
    server.Put(R"(/.*)", other_method);
    server.Patch(R"(/.*)", other_method);
    server.Delete(R"(/.*)", other_method);
  }
};

StudioServer::StudioServer(const StudioOptions& options) : impl_(std::make_unique<Impl>()) {
  options.Check();
  Impl& m = *impl_;
  m.options = options;
  m.workspace = std::make_unique<Workspace>(options.root.empty() ? fs::current_path()
                                                                 : fs::path(options.root));
  std::string program = options.program;
  if (program.empty()) program = util::ProgramPath().string();
  FV_REQUIRE(!program.empty(), "studio: cannot tell where the fieldvision program is");
  m.jobs = std::make_unique<JobRunner>(program, *m.workspace, &m.events);
  m.live = std::make_unique<LiveFeed>(&m.events);
  m.api = std::make_unique<StudioApi>(*m.workspace, &m.events, m.jobs.get(), m.live.get());
  if (m.options.assets.empty()) m.options.assets = DefaultAssetsDir().string();
  m.assets_built = fs::is_regular_file(fs::path(m.options.assets) / "index.html");
  m.token_required = !IsLoopback(options.host);
  if (m.token_required && m.options.token.empty()) m.options.token = RandomToken();

  httplib::Server& s = m.server;
  s.new_task_queue = [] { return new httplib::ThreadPool(kThreads); };
  s.set_payload_max_length(32 << 20);
  s.set_read_timeout(10);
  // SO_REUSEADDR only: httplib's default SO_REUSEPORT would let a second studio share the port.
  s.set_socket_options([](int sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  m.AddEventStream();
  m.AddApi();
  // Errors httplib answers itself (a page or file that is not there, a bad request line) get
  // one line saying what, as the API's do, instead of an empty body.
  s.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;
    const std::string path = util::Shown(req.path);
    const nlohmann::json error = {{"error", res.status == 404
                                                ? fmt::format("not found: {}", path)
                                                : fmt::format("HTTP {} for {}", res.status, path)}};
    res.set_content(error.dump(), "application/json");
  });
  if (m.assets_built) {
    s.set_mount_point("/", m.options.assets);
  } else {
    s.Get("/", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(NotBuiltPage(impl_->options.assets), "text/html");
    });
  }
}

StudioServer::~StudioServer() { Stop(); }

int StudioServer::Start() {
  Impl& m = *impl_;
  FV_REQUIRE(m.port < 0, "studio: server already started");
  if (!m.options.live.empty()) {
    try {
      m.live->Start(m.options.live);
    } catch (const HttpError& e) {
      Throw("studio: --live: {}", e.what());
    }
  }
  if (m.options.port == 0) {
    m.port = m.server.bind_to_any_port(m.options.host);
  } else {
    m.port = m.server.bind_to_port(m.options.host, m.options.port) ? m.options.port : -1;
  }
  FV_REQUIRE(m.port > 0, "studio: cannot listen on {}:{} (address in use or not this machine's)",
             m.options.host, m.options.port);
  m.thread = std::thread([this] {
    impl_->server.listen_after_bind();
    impl_->loop_ended = true;
  });
  // httplib's stop() does nothing before the loop runs: wait for it, so Stop() always ends it.
  while (!m.server.is_running() && !m.loop_ended) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return m.port;
}

void StudioServer::Stop() {
  Impl& m = *impl_;
  m.live->Stop();
  m.events.Close();
  if (m.thread.joinable()) {
    m.server.stop();
    m.thread.join();
  }
}

int StudioServer::port() const { return impl_->port; }
bool StudioServer::token_required() const { return impl_->token_required; }
const std::string& StudioServer::token() const { return impl_->options.token; }
bool StudioServer::assets_built() const { return impl_->assets_built; }
const std::string& StudioServer::assets_dir() const { return impl_->options.assets; }
EventHub& StudioServer::events() { return impl_->events; }

std::string StudioServer::Url() const {
  const std::string& h = impl_->options.host;
  const std::string host = h.find(':') != std::string::npos ? "[" + h + "]" : h;
  std::string url = fmt::format("http://{}:{}/", host, impl_->port);
  if (impl_->token_required) url += "?token=" + impl_->options.token;
  return url;
}

int RunStudio(const StudioOptions& options, std::ostream& out) {
  // Block the stop signals in every thread (the server's inherit the mask) and wait for them.
  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGINT);
  sigaddset(&stop, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop, nullptr);
  StudioServer server(options);
  server.Start();
  out << "fieldvision studio: working folder " << fs::current_path().string() << "\n";
  if (!server.assets_built()) {
    out << "fieldvision studio: the front end is not built (" << server.assets_dir()
        << "/index.html missing): run `make build` with Node.js and npm installed; the page says "
           "so too\n";
  }
  out << "fieldvision studio: open " << server.Url() << "  (Ctrl-C stops)" << std::endl;
  int sig = 0;
  sigwait(&stop, &sig);
  out << "fieldvision studio: stopping" << std::endl;
  server.Stop();
  return 0;
}

}  // namespace fv::web
