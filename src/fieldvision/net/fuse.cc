#include "fieldvision/net/fuse.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <utility>

#include <fmt/format.h>
#include <zmq.hpp>

#include "fieldvision/camera/frame_size.h"
#include "fieldvision/io/frame_source.h"
#include "fieldvision/net/messages.h"
#include "fieldvision/pipeline/ball_job.h"
#include "fieldvision/recon/ball_csv.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/strings.h"

namespace fv::net {

void FuseOptions::Check() const {
  FV_REQUIRE(util::StartsWith(listen, "tcp://") || util::StartsWith(listen, "ipc://"),
             "fuse: --listen must be tcp://HOST:PORT (got '{}')", listen);
  FV_REQUIRE(
      publish.empty() || util::StartsWith(publish, "tcp://") || util::StartsWith(publish, "ipc://"),
      "fuse: --publish must be tcp://HOST:PORT (got '{}')", publish);
  FV_REQUIRE(!cameras.empty(), "fuse: give at least one --camera");
  FV_REQUIRE(cameras.size() >= 2 || triangulation.single_camera_ground,
             "fuse: one camera gives no 3D position: give 2 or more --camera");
  FV_REQUIRE(std::isfinite(media_max_wait_s) && media_max_wait_s >= 0 && media_max_wait_s <= 9,
             "fuse: --media-max-wait must be in [0, 9] s (got {})", media_max_wait_s);
  FV_REQUIRE(!out.empty(), "fuse: --out is required");
  FV_REQUIRE(std::isfinite(idle_exit_s) && idle_exit_s >= 0, "fuse: --idle-exit must be >= 0");
  FV_REQUIRE(std::isfinite(ball_diameter_m) && ball_diameter_m > 0 && ball_diameter_m < 2,
             "fuse: --ball-diameter must be in (0, 2) metres (got {})", ball_diameter_m);
  sync.Check();
  flight_options.Check();
  triangulation.Check();
}

std::string FuseSummary::ToString() const {
  std::string s = fmt::format(
      "{} frames fused, {} with a ball position ({:.1f} %), mean reprojection error {:.2f} px",
      fusion.frames, fusion.frames_with_position,
      fusion.frames ? 100.0 * fusion.frames_with_position / fusion.frames : 0.0,
      fusion.frames_with_position ? fusion.sum_err_px / fusion.frames_with_position : 0.0);
  for (size_t c = 0; c < cameras.size(); ++c) {
    const FuseCameraReport& r = cameras[c];
    s += fmt::format("\n{}: {} frames, {} positions", r.name, r.frames,
                     c < fusion.used_per_camera.size() ? fusion.used_per_camera[c] : 0);
    if (r.has_offset) s += fmt::format(", clock offset {:+.4f} s", r.offset_s);
    if (r.sessions > 1) s += fmt::format(", {} sessions (restarted)", r.sessions);
    if (r.refused > 0) {
      s += fmt::format(
          ", {} messages ignored (a second node as this camera, or another image "
          "size)",
          r.refused);
    }
  }
  for (const std::string& p : sync_problems) s += "\nsync: " + p;
  const long long refused =
      malformed + oversized + wrong_version + unknown_camera + unsynced + clock_mismatch;
  if (refused > 0) {
    s += fmt::format(
        "\nmessages dropped: {} malformed, {} oversized, {} of another schema version, {} from "
        "unknown cameras, {} before a clock estimate, {} on another clock",
        malformed, oversized, wrong_version, unknown_camera, unsynced, clock_mismatch);
  }
  if (!latency_s.empty()) {
    s += fmt::format("\nlatency capture -> fused: p50 {:.1f} ms, p95 {:.1f} ms ({} frames)",
                     1e3 * util::NearestRankPercentile(latency_s, 0.5),
                     1e3 * util::NearestRankPercentile(latency_s, 0.95), latency_s.size());
    // Each part: the slowest camera of the frame (p50 / p95 over frames).
    std::vector<double> queued, process, arrival, pairing;
    for (const LatencyParts& p : latency_parts) {
      if (p.queued_s >= 0) queued.push_back(p.queued_s);
      if (p.process_s >= 0) process.push_back(p.process_s);
      arrival.push_back(p.arrival_s);
      pairing.push_back(p.pairing_s);
    }
    const auto pp = [](const std::vector<double>& v) {
      return v.empty() ? std::string("n/a")
                       : fmt::format("{:.1f}/{:.1f}", 1e3 * util::NearestRankPercentile(v, 0.5),
                                     1e3 * util::NearestRankPercentile(v, 0.95));
    };
    s += fmt::format(
        "\n  where it goes (ms, p50/p95, slowest camera of each frame): waiting in the nodes' "
        "source {}, the nodes' work {}, capture -> last message here {}, pairing and fusion {}",
        pp(queued), pp(process), pp(arrival), pp(pairing));
  }
  s += fmt::format("\n{} messages in {:.2f} s", messages, seconds);
  if (published > 0) s += fmt::format(", {} positions published", published);
  if (hints_sent > 0) s += fmt::format(", {} hints sent to the nodes", hints_sent);
  if (!flights.empty()) {
    s += fmt::format("\n{} flights ({} published)", flights.size(), flights_published);
  }
  return s;
}

namespace {

// The flight analysis, in its own thread so that it never delays a position: positions in,
// closed flights out.
class FlightWorker {
 public:
  explicit FlightWorker(const pipeline::LiveFlightsOptions& options)
      : flights_(options), thread_([this] { Run(); }) {}
  ~FlightWorker() { Finish(); }
  void Add(const recon::BallSample& s) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (in_.size() < 100000) in_.push_back(s);
    }
    cv_.notify_one();
  }
  // Flights closed so far (taken).
  std::vector<recon::Flight> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(out_, {});
  }
  // Analyses what is left, ends the thread; then Take() has the rest.
  void Finish() {
    if (!thread_.joinable()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    cv_.notify_one();
    thread_.join();
  }

 private:
  void Run() {
    for (;;) {
      std::deque<recon::BallSample> batch;
      bool done = false;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [&] { return done_ || !in_.empty(); });
        batch.swap(in_);
        done = done_;
      }
      std::vector<recon::Flight> closed;
      for (const recon::BallSample& s : batch) {
        for (recon::Flight& f : flights_.Add(s)) closed.push_back(std::move(f));
      }
      if (done) {
        for (recon::Flight& f : flights_.Finish()) closed.push_back(std::move(f));
      }
      if (!closed.empty()) {
        std::lock_guard<std::mutex> lock(mutex_);
        for (recon::Flight& f : closed) out_.push_back(std::move(f));
      }
      if (done) return;
    }
  }
  pipeline::LiveFlights flights_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<recon::BallSample> in_;
  std::vector<recon::Flight> out_;
  bool done_ = false;
  std::thread thread_;
};

FlightMessage ToMessage(const recon::Flight& f, long long index) {
  FlightMessage m;
  m.index = index;
  m.start = recon::FlightEventName(f.start_event);
  m.end = recon::FlightEventName(f.end_event);
  m.t_start_s = f.t_start_s;
  m.t_end_s = f.t_end_s;
  for (int i = 0; i < 3; ++i) {
    m.origin_m[i] = f.origin_m[i];
    m.landing_m[i] = f.landing_m[i];
    m.apex_m[i] = f.apex_m[i];
    m.v0_mps[i] = f.v0_mps[i];
  }
  m.t_landing_s = f.t_landing_s;
  m.landing_extrapolated = f.landing_extrapolated;
  m.speed_mps = f.speed_mps;
  m.rmse_m = f.rmse_m;
  m.model = recon::FlightModelName(f.model_kind());
  m.samples = static_cast<long long>(f.samples.size());
  return m;
}

double SteadyNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

std::optional<std::pair<std::string, std::string>> SenderOf(const Message& m) {
  if (const auto* ping = std::get_if<PingMessage>(&m)) return {{ping->camera, ping->session}};
  if (const auto* f = std::get_if<FrameMessage>(&m)) return {{f->camera, f->session}};
  if (const auto* k = std::get_if<SkipMessage>(&m)) return {{k->camera, k->session}};
  if (const auto* h = std::get_if<HelloMessage>(&m)) return {{h->camera, h->session}};
  if (const auto* b = std::get_if<ByeMessage>(&m)) return {{b->camera, b->session}};
  return std::nullopt;  // a pong, ball, flight or hint message
}

namespace {

// Where each frame's latency goes (system clocks only): the node's queue and work times and the
// message's arrival on this clock, kept per camera and frame until its group is decided.
struct FrameTiming {
  double queued_s = -1, process_s = -1, arrival_s = 0;
};

// The fusion server of RunFuse: its sockets, the synchronizer, fusion and outputs.
class FuseServer {
 public:
  explicit FuseServer(const FuseOptions& o);
  // Receives, pairs and fuses until stopped or idle; then flushes and closes the outputs.
  FuseSummary Run();

 private:
  void Bind();
  // One message from a node (`t1`: its arrival on the system clock, `arrival`: steady clock).
  void Receive(zmq::message_t& identity, const zmq::message_t& payload, double t1, double arrival);
  // One camera frame message of camera c.
  void AddFrame(int c, const FrameMessage& f, double t1, double arrival);
  // Whether `session` may speak for camera c now: a second node sending as a camera whose node
  // goes on is refused (warned once), a new session after the old one ended or went quiet is
  // the camera restarted.
  bool AcceptSession(int c, const std::string& session, double arrival);
  // Why the node of `camera` is not heard (told in its pongs), "" when it is: an unknown camera,
  // another image size than the camera file's, or (`for_now`) a second node of one camera. Sets
  // `c` to the camera's index when it is known.
  std::string Admit(const Message& m, const std::string& camera, const std::string& session,
                    const std::string& id, double arrival, int* c, bool* for_now);
  // A hello whose image size is not the camera file's: warned once, the camera's frames refused.
  void CheckHello(int c, const HelloMessage& h);
  // One warning per kind of dropped message while running (all are counted in the summary).
  void WarnDropped(const std::string& kind, const std::string& what);
  void Emit(const pipeline::SyncedFrame& group);
  FuseSummary::LatencyParts LatencyPartsOf(const pipeline::SyncedFrame& group, double latency_s);
  void PublishFlights();
  // A hint (messages.h) to every node that has sent a message.
  void SendHint(const HintMessage& hint);
  void ReportProgress(double now);

  const FuseOptions& o_;
  std::vector<camera::Camera> cameras_;
  std::map<std::string, int> index_;
  int n_ = 0;
  std::unique_ptr<pipeline::FusionStage> fusion_;
  std::unique_ptr<pipeline::LiveSynchronizer> sync_;
  FuseSummary summary_;
  std::vector<std::string> names_;
  std::vector<std::string> sessions_;
  std::vector<double> session_heard_s_;  // the current session's last message (steady clock)
  std::vector<bool> session_ended_;      // it said bye
  std::vector<std::string> identities_;  // each camera's node (its ROUTER routing id), for hints
  std::set<int> warned_second_node_;
  std::map<int, std::string> size_refused_;  // cameras whose node sends another image size: why
  std::set<std::string> warned_dropped_;     // kinds of dropped messages warned about
  std::set<std::string> warned_unknown_;
  std::string clock_kind_;  // "system" or "media", from the first frame
  zmq::context_t ctx_{1};
  zmq::socket_t router_;
  zmq::socket_t pub_;
  std::vector<std::map<long long, FrameTiming>> timings_;
  std::unique_ptr<FlightWorker> flight_worker_;
  util::CsvWriter* csv_ = nullptr;  // BALL.csv, while Run runs
  double last_report_ = 0;
  // On a terminal, frames fused so far; quiet in a log (a fusion node runs for hours).
  std::optional<util::Progress> progress_;
};

FuseServer::FuseServer(const FuseOptions& o) : o_(o) {
  for (const std::string& path : o.cameras) {
    cameras_.push_back(pipeline::ReadRigCamera(path));
    FV_REQUIRE(index_.emplace(cameras_.back().name, static_cast<int>(cameras_.size()) - 1).second,
               "fuse: two cameras are named '{}' (set `name` in the camera files)",
               cameras_.back().name);
  }
  if (!o.triangulation.single_camera_ground) pipeline::CheckRigSpread(cameras_, o.cameras);
  n_ = static_cast<int>(cameras_.size());
  recon::TriangulationOptions topt = o.triangulation;
  topt.ball_radius_m = 0.5 * o.ball_diameter_m;
  fusion_ = std::make_unique<pipeline::FusionStage>(cameras_, topt);
  sync_ = std::make_unique<pipeline::LiveSynchronizer>(n_, o.sync);
  summary_.cameras.resize(n_);
  for (int c = 0; c < n_; ++c) {
    summary_.cameras[c].name = cameras_[c].name;
    names_.push_back(cameras_[c].name);
  }
  sessions_.resize(n_);
  session_heard_s_.assign(n_, -1e300);
  session_ended_.assign(n_, false);
  identities_.resize(n_);
  timings_.resize(n_);
}

namespace {

// What to do about a failed bind, for the errors a user's address causes.
std::string BindAdvice(int error) {
  switch (error) {
    case ENODEV:
    case EADDRNOTAVAIL:
      return " (give an address of this machine: tcp://*:PORT listens on all its networks)";
    case EADDRINUSE:
      return " (another program, or another fuse, listens there: give another PORT)";
    case EACCES:
      return " (ports below 1024 need administrator rights: give a PORT from 1024)";
    default:
      return "";
  }
}

}  // namespace

void FuseServer::Bind() {
  router_ = zmq::socket_t(ctx_, zmq::socket_type::router);
  router_.set(zmq::sockopt::linger, 0);
  router_.set(zmq::sockopt::rcvhwm, 10000);
  // Far larger messages are cut off by ZeroMQ (the peer is disconnected, then reconnects).
  router_.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(16 * kMaxMessageBytes));
  try {
    router_.bind(o_.listen);
  } catch (const zmq::error_t& e) {
    Throw("fuse: cannot listen on '{}': {}{}", o_.listen, e.what(), BindAdvice(e.num()));
  }
  if (o_.on_listening) o_.on_listening(router_.get(zmq::sockopt::last_endpoint));
  if (o_.publish.empty()) return;
  pub_ = zmq::socket_t(ctx_, zmq::socket_type::pub);
  pub_.set(zmq::sockopt::linger, 0);
  pub_.set(zmq::sockopt::sndhwm, 1000);
  try {
    pub_.bind(o_.publish);
  } catch (const zmq::error_t& e) {
    Throw("fuse: cannot publish on '{}': {}{}", o_.publish, e.what(), BindAdvice(e.num()));
  }
}

FuseSummary::LatencyParts FuseServer::LatencyPartsOf(const pipeline::SyncedFrame& group,
                                                     double latency_s) {
  FuseSummary::LatencyParts parts;
  for (int c = 0; c < n_; ++c) {
    if (!group.cameras[c]) continue;
    auto& t = timings_[c];
    const auto it = t.find(group.cameras[c]->frame);
    if (it == t.end()) continue;
    const FrameTiming& m = it->second;
    parts.queued_s = std::max(parts.queued_s, m.queued_s);
    parts.process_s = std::max(parts.process_s, m.process_s);
    parts.arrival_s = std::max(parts.arrival_s, m.arrival_s - group.cameras[c]->time_s);
    t.erase(t.begin(), std::next(it));
  }
  parts.pairing_s = latency_s - parts.arrival_s;
  return parts;
}

void FuseServer::Emit(const pipeline::SyncedFrame& group) {
  const pipeline::BallFrame f = fusion_->Fuse(group);
  ++summary_.groups;
  summary_.paired_groups += group.present() >= 2;
  // Capture to decision, for every frame fused (with a position or not).
  const double decided_s = io::SystemClockNow();
  const double latency_s = clock_kind_ == "system" ? decided_s - group.time_s : 0.0;
  if (clock_kind_ == "system") {
    summary_.latency_s.push_back(latency_s);
    summary_.latency_parts.push_back(LatencyPartsOf(group, latency_s));
  }
  if (!f.result.ok()) {
    if (o_.hints) SendHint(HintMessage{.time_s = f.time_s, .lost = true});
    return;
  }
  const Eigen::Vector3d& p = f.result.point_world;
  *csv_ << f.frame << f.time_s << p.x() << p.y() << p.z() << f.result.num_views()
        << f.result.rms_px;
  csv_->EndRow();
  ++summary_.rows_written;
  const BallMessage b{f.frame,         f.time_s, p.x(), p.y(), p.z(), f.result.num_views(),
                      f.result.rms_px, latency_s};
  if (pub_) {
    const std::string topic = "ball";
    pub_.send(zmq::buffer(topic), zmq::send_flags::sndmore | zmq::send_flags::dontwait);
    if (pub_.send(zmq::buffer(Encode(b)), zmq::send_flags::dontwait)) ++summary_.published;
  }
  if (flight_worker_) flight_worker_->Add(pipeline::BallSampleOf(f));
  // A single camera's ground guess is no position of the cameras together.
  if (o_.hints) {
    SendHint(HintMessage{.time_s = f.time_s,
                         .x_m = p.x(),
                         .y_m = p.y(),
                         .z_m = p.z(),
                         .radius_m = 0.5 * o_.ball_diameter_m,
                         .lost = f.result.on_ground});
  }
}

void FuseServer::SendHint(const HintMessage& hint) {
  const std::string bytes = Encode(hint);
  for (const std::string& id : identities_) {
    if (id.empty()) continue;
    if (!router_.send(zmq::buffer(id), zmq::send_flags::sndmore | zmq::send_flags::dontwait)) {
      continue;
    }
    if (router_.send(zmq::buffer(bytes), zmq::send_flags::dontwait)) ++summary_.hints_sent;
  }
}

void FuseServer::PublishFlights() {
  if (!flight_worker_) return;
  for (recon::Flight& flight : flight_worker_->Take()) {
    const FlightMessage m = ToMessage(flight, static_cast<long long>(summary_.flights.size()));
    summary_.flights.push_back(std::move(flight));
    if (!pub_) continue;
    const std::string topic = "flight";
    pub_.send(zmq::buffer(topic), zmq::send_flags::sndmore | zmq::send_flags::dontwait);
    if (pub_.send(zmq::buffer(Encode(m)), zmq::send_flags::dontwait)) {
      ++summary_.flights_published;
    }
  }
}

void FuseServer::Receive(zmq::message_t& identity, const zmq::message_t& payload, double t1,
                         double arrival) {
  ++summary_.messages;
  Message m;
  try {
    m = Decode(payload.data(), payload.size());
  } catch (const MessageError& e) {
    switch (e.reason()) {
      case MessageError::Reason::kOversized:
        ++summary_.oversized;
        WarnDropped("oversized", e.what());
        break;
      case MessageError::Reason::kVersion:
        ++summary_.wrong_version;
        WarnDropped("version", e.what());
        break;
      case MessageError::Reason::kMalformed:
        ++summary_.malformed;
        WarnDropped("malformed", e.what());
        break;
    }
    return;
  }
  // Every message but a pong or a ball names its camera and session.
  const auto sender = SenderOf(m);
  if (!sender) {
    ++summary_.malformed;  // a pong or a ball message sent to us
    return;
  }
  const auto& [camera, session] = *sender;
  const std::string id = identity.to_string();
  int c = -1;
  bool for_now = false;
  const std::string refused = Admit(m, camera, session, id, arrival, &c, &for_now);
  if (const auto* ping = std::get_if<PingMessage>(&m)) {
    PongMessage pong{ping->t0_s, t1, 0, o_.hints, refused, for_now};
    pong.t2_s = io::SystemClockNow();
    // A copy of the routing id: sending a zmq message empties it.
    router_.send(zmq::buffer(id), zmq::send_flags::sndmore | zmq::send_flags::dontwait);
    router_.send(zmq::buffer(Encode(pong)), zmq::send_flags::dontwait);
  }
  if (!refused.empty()) return;
  if (const auto* hello = std::get_if<HelloMessage>(&m)) sync_->SetFrameRate(c, hello->fps);
  if (std::holds_alternative<PingMessage>(m) || std::holds_alternative<HelloMessage>(m)) {
    sync_->Admit(c, arrival);  // connected: its frames are waited for
    return;
  }
  if (std::holds_alternative<ByeMessage>(m)) {
    session_ended_[c] = true;
    sync_->EndOfStream(c);
    return;
  }
  if (const auto* k = std::get_if<SkipMessage>(&m)) {
    if (k->clock != clock_kind_ && !clock_kind_.empty()) return;
    if (k->clock == "system" && !k->has_offset) return;
    sync_->SkipUntil(c, k->time_s + (k->clock == "system" ? k->offset_s : 0.0), arrival);
    return;
  }
  AddFrame(c, std::get<FrameMessage>(m), t1, arrival);
}

std::string FuseServer::Admit(const Message& m, const std::string& camera,
                              const std::string& session, const std::string& id, double arrival,
                              int* c, bool* for_now) {
  const auto it = index_.find(camera);
  if (it == index_.end()) {
    ++summary_.unknown_camera;
    if (warned_unknown_.insert(camera).second && warned_unknown_.size() <= 10) {
      std::cerr << fmt::format("fuse: warning: messages from unknown camera '{}' ignored\n",
                               camera);
    }
    std::string names;
    for (size_t k = 0; k < names_.size() && names.size() < 200; ++k) {
      names += (k > 0 ? ", " : "") + names_[k];
    }
    return fmt::format("it has no camera '{}' (its cameras: {})", camera.substr(0, 100), names);
  }
  *c = it->second;
  if (!AcceptSession(*c, session, arrival)) {
    *for_now = true;
    return fmt::format(
        "another node sends as camera '{}' and goes on (give each node its own camera file)",
        camera);
  }
  identities_[*c] = id;
  if (const auto* hello = std::get_if<HelloMessage>(&m)) CheckHello(*c, *hello);
  if (const auto size = size_refused_.find(*c); size != size_refused_.end()) {
    ++summary_.cameras[*c].refused;  // frames of another image size than its camera file's
    return size->second;
  }
  return "";
}

bool FuseServer::AcceptSession(int c, const std::string& session, double arrival) {
  // A node pings every 0.5 s: quiet this long, it is gone (killed, unplugged).
  constexpr double kGoneAfterS = 1.5;
  if (sessions_[c] != session) {
    if (!sessions_[c].empty() && !session_ended_[c] &&
        arrival - session_heard_s_[c] < kGoneAfterS) {
      ++summary_.cameras[c].refused;
      if (warned_second_node_.insert(c).second) {
        std::cerr << fmt::format(
            "fuse: warning: another node sends as camera '{}' while its node goes on (a second "
            "node, or one restarted within 1.5 s): its messages are ignored until the first has "
            "been quiet for 1.5 s (give each node its own camera file)\n",
            names_[c]);
      }
      return false;
    }
    if (!sessions_[c].empty()) sync_->Restart(c);
    sessions_[c] = session;
    session_ended_[c] = false;
    size_refused_.erase(c);
    ++summary_.cameras[c].sessions;
  }
  session_heard_s_[c] = arrival;
  return true;
}

void FuseServer::CheckHello(int c, const HelloMessage& h) {
  const camera::Camera& cam = cameras_[c];
  if (h.width <= 0 || h.height <= 0 || (h.width == cam.width && h.height == cam.height)) return;
  // The node fitted the same camera file to its video (camera::FitCameraToFrames).
  if (camera::IsCroppedPadding(cam, h.width, h.height)) return;
  if (size_refused_.count(c) > 0) return;
  size_refused_[c] = fmt::format(
      "it sends {}x{} images but the camera file of '{}' there is for {}x{} (give fuse and the "
      "node the same camera file)",
      h.width, h.height, names_[c], cam.width, cam.height);
  std::cerr << fmt::format(
      "fuse: warning: the node of camera '{}' sends {}x{} images but its camera file here is for "
      "{}x{}: its frames are ignored (give fuse and the node the same camera file)\n",
      names_[c], h.width, h.height, cam.width, cam.height);
}

void FuseServer::WarnDropped(const std::string& kind, const std::string& what) {
  if (!warned_dropped_.insert(kind).second) return;
  std::cerr << fmt::format("fuse: warning: message dropped: {} (more are counted at the end)\n",
                           what);
}

void FuseServer::AddFrame(int c, const FrameMessage& f, double t1, double arrival) {
  FuseCameraReport& r = summary_.cameras[c];
  ++r.frames;
  if (clock_kind_.empty()) {
    clock_kind_ = f.clock;
    if (clock_kind_ == "media" && o_.media_max_wait_s > o_.sync.max_wait_s) {
      sync_->SetMaxWait(o_.media_max_wait_s);
    }
  }
  if (f.clock != clock_kind_) {
    ++summary_.clock_mismatch;
    return;
  }
  pipeline::CameraMessage cm;
  cm.camera = c;
  cm.frame = f.frame;
  cm.time_s = f.time_s;
  if (f.clock == "system") {
    if (!f.has_offset) {
      ++summary_.unsynced;
      return;
    }
    cm.time_s += f.offset_s;
    r.has_offset = true;
    r.offset_s = f.offset_s;
  }
  cm.candidates = f.candidates;
  if (f.clock == "system") {
    auto& t = timings_[c];
    if (t.size() >= 1000) t.erase(t.begin());  // frames that never make a group
    t[cm.frame] = {f.queued_s, f.process_s, t1};
  }
  sync_->Add(std::move(cm), arrival);
}

void FuseServer::ReportProgress(double now) {
  if (now - last_report_ <= 0.5) return;
  last_report_ = now;
  if (o_.control != nullptr) {
    o_.control->Report({"fuse", fusion_->stats().frames, -1, "frames", ""});
  }
  if (progress_) progress_->Update(fusion_->stats().frames);
}

FuseSummary FuseServer::Run() {
  Bind();
  if (o_.progress) progress_.emplace("fuse", -1, "frames fused");
  if (o_.flights) {
    pipeline::LiveFlightsOptions fopt = o_.flight_options;
    fopt.analysis.ball_radius_m = 0.5 * o_.ball_diameter_m;
    flight_worker_ = std::make_unique<FlightWorker>(fopt);
  }
  // Written beside --out and renamed at the end; a run that fails leaves no temporary file.
  util::AtomicOutput out_file(o_.out);
  util::CsvWriter csv(out_file.temp_path(), recon::BallCsvColumns(), 6);
  csv_ = &csv;
  const auto start = std::chrono::steady_clock::now();
  double last_message = SteadyNow();
  std::vector<zmq::pollitem_t> items = {{router_.handle(), 0, ZMQ_POLLIN, 0}};
  while (!StopRequested(o_.control)) {
    try {
      zmq::poll(items, std::chrono::milliseconds(2));
    } catch (const zmq::error_t& e) {
      if (e.num() != EINTR) throw;
      continue;  // a signal (Ctrl-C, SIGTERM): StopRequested decides
    }
    zmq::message_t identity, payload;
    // At most this many messages a turn: a flood does not hold off pairing and the stop check.
    constexpr int kMaxMessagesPerTurn = 1000;
    int taken = 0;
    while (taken++ < kMaxMessagesPerTurn && router_.recv(identity, zmq::recv_flags::dontwait)) {
      const double t1 = io::SystemClockNow();
      const double arrival = SteadyNow();
      last_message = arrival;
      if (!identity.more() || !router_.recv(payload, zmq::recv_flags::dontwait)) {
        ++summary_.malformed;
        continue;
      }
      while (payload.more()) {  // extra parts: not our protocol
        zmq::message_t extra;
        if (!router_.recv(extra, zmq::recv_flags::dontwait)) break;
        payload.rebuild(extra.data(), extra.size());
        ++summary_.malformed;
      }
      Receive(identity, payload, t1, arrival);
    }
    const double now = SteadyNow();
    while (auto group = sync_->Next(now)) Emit(*group);
    PublishFlights();
    if (o_.idle_exit_s > 0 && summary_.messages > 0 && now - last_message > o_.idle_exit_s) break;
    ReportProgress(now);
  }
  if (progress_) progress_->Finish();
  while (auto group = sync_->Next(SteadyNow(), /*flush=*/true)) Emit(*group);
  if (flight_worker_) {
    flight_worker_->Finish();
    PublishFlights();
  }
  csv_ = nullptr;
  // Without a single frame fused (nodes pointed elsewhere, stopped before any came, or only one
  // camera delivered and gave no position) an earlier file stays as it was.
  summary_.written = summary_.rows_written > 0 || summary_.paired_groups > 0;
  if (summary_.written) out_file.CloseAndCommit(csv);
  summary_.fusion = fusion_->stats();
  summary_.sync = sync_->stats();
  summary_.sync_problems = sync_->Problems(names_);
  summary_.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return std::move(summary_);
}

}  // namespace

FuseSummary RunFuse(const FuseOptions& o) {
  o.Check();
  FuseServer server(o);
  return server.Run();
}

}  // namespace fv::net
