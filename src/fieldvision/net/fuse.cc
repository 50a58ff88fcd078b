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
#include <set>
#include <thread>
#include <utility>

#include <fmt/format.h>
#include <zmq.hpp>

#include "fieldvision/io/frame_source.h"
#include "fieldvision/io/output_path.h"
#include "fieldvision/net/messages.h"
#include "fieldvision/pipeline/ball_job.h"
#include "fieldvision/recon/ball_csv.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::net {

void FuseOptions::Check() const {
  FV_REQUIRE(StartsWith(listen, "tcp://") || StartsWith(listen, "ipc://"),
             "fuse: --listen must be tcp://HOST:PORT (got '{}')", listen);
  FV_REQUIRE(publish.empty() || StartsWith(publish, "tcp://") || StartsWith(publish, "ipc://"),
             "fuse: --publish must be tcp://HOST:PORT (got '{}')", publish);
  FV_REQUIRE(!cameras.empty(), "fuse: give at least one --camera");
  FV_REQUIRE(!out.empty(), "fuse: --out is required");
  FV_REQUIRE(std::isfinite(idle_exit_s) && idle_exit_s >= 0, "fuse: --idle-exit must be >= 0");
  FV_REQUIRE(std::isfinite(ball_diameter_m) && ball_diameter_m > 0 && ball_diameter_m < 2,
             "fuse: --ball-diameter must be in (0, 2) metres (got {})", ball_diameter_m);
  sync.Check();
  flight_options.Check();
  triangulation.Check();
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double rank = std::ceil(p / 100.0 * static_cast<double>(v.size()));
  const size_t i = static_cast<size_t>(std::clamp(rank, 1.0, static_cast<double>(v.size()))) - 1;
  return v[i];
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
                     1e3 * Percentile(latency_s, 50), 1e3 * Percentile(latency_s, 95),
                     latency_s.size());
    // Each part: the slowest camera of the frame (p50 / p95 over frames).
    std::vector<double> queued, process, arrival, pairing;
    for (const LatencyParts& p : latency_parts) {
      if (p.queued_s >= 0) queued.push_back(p.queued_s);
      if (p.process_s >= 0) process.push_back(p.process_s);
      arrival.push_back(p.arrival_s);
      pairing.push_back(p.pairing_s);
    }
    const auto pp = [](const std::vector<double>& v) {
      return v.empty()
                 ? std::string("n/a")
                 : fmt::format("{:.1f}/{:.1f}", 1e3 * Percentile(v, 50), 1e3 * Percentile(v, 95));
    };
    s += fmt::format(
        "\n  where it goes (ms, p50/p95, slowest camera of each frame): waiting in the nodes' "
        "source {}, the nodes' work {}, capture -> last message here {}, pairing and fusion {}",
        pp(queued), pp(process), pp(arrival), pp(pairing));
  }
  s += fmt::format("\n{} messages in {:.2f} s", messages, seconds);
  if (published > 0) s += fmt::format(", {} positions published", published);
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
  explicit FlightWorker(const LiveFlightsOptions& options)
      : flights_(options), thread_([this] { Run(); }) {}
  ~FlightWorker() { Finish(); }
  void Add(const BallSample& s) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (in_.size() < 100000) in_.push_back(s);
    }
    cv_.notify_one();
  }
  // Flights closed so far (taken).
  std::vector<Flight> Take() {
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
      std::deque<BallSample> batch;
      bool done = false;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [&] { return done_ || !in_.empty(); });
        batch.swap(in_);
        done = done_;
      }
      std::vector<Flight> closed;
      for (const BallSample& s : batch) {
        for (Flight& f : flights_.Add(s)) closed.push_back(std::move(f));
      }
      if (done) {
        for (Flight& f : flights_.Finish()) closed.push_back(std::move(f));
      }
      if (!closed.empty()) {
        std::lock_guard<std::mutex> lock(mutex_);
        for (Flight& f : closed) out_.push_back(std::move(f));
      }
      if (done) return;
    }
  }
  LiveFlights flights_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<BallSample> in_;
  std::vector<Flight> out_;
  bool done_ = false;
  std::thread thread_;
};

FlightMessage ToMessage(const Flight& f, long long index) {
  FlightMessage m;
  m.index = index;
  m.start = FlightEventName(f.start_event);
  m.end = FlightEventName(f.end_event);
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
  m.model = FlightModelName(f.model_kind());
  m.samples = static_cast<long long>(f.samples.size());
  return m;
}

double SteadyNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

FuseSummary RunFuse(const FuseOptions& o) {
  o.Check();
  std::vector<Camera> cameras;
  std::map<std::string, int> index;
  for (const std::string& path : o.cameras) {
    cameras.push_back(ReadRigCamera(path));
    FV_REQUIRE(index.emplace(cameras.back().name, static_cast<int>(cameras.size()) - 1).second,
               "fuse: two cameras are named '{}' (set `name` in the camera files)",
               cameras.back().name);
  }
  const int n = static_cast<int>(cameras.size());
  TriangulationOptions topt = o.triangulation;
  topt.ball_radius_m = 0.5 * o.ball_diameter_m;
  FusionStage fusion(cameras, topt);
  LiveSynchronizer sync(n, o.sync);

  FuseSummary summary;
  summary.cameras.resize(n);
  std::vector<std::string> names;
  for (int c = 0; c < n; ++c) {
    summary.cameras[c].name = cameras[c].name;
    names.push_back(cameras[c].name);
  }
  std::vector<std::string> sessions(n);
  std::set<std::string> warned_unknown;
  std::string clock_kind;  // "system" or "media", from the first frame

  zmq::context_t ctx(1);
  zmq::socket_t router(ctx, zmq::socket_type::router);
  router.set(zmq::sockopt::linger, 0);
  router.set(zmq::sockopt::rcvhwm, 10000);
  // Far larger messages are cut off by ZeroMQ (the peer is disconnected, then reconnects).
  router.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(16 * kMaxMessageBytes));
  try {
    router.bind(o.listen);
  } catch (const zmq::error_t& e) {
    Throw("fuse: cannot listen on '{}': {}", o.listen, e.what());
  }
  if (o.on_listening) o.on_listening(router.get(zmq::sockopt::last_endpoint));
  zmq::socket_t pub;
  if (!o.publish.empty()) {
    pub = zmq::socket_t(ctx, zmq::socket_type::pub);
    pub.set(zmq::sockopt::linger, 0);
    pub.set(zmq::sockopt::sndhwm, 1000);
    try {
      pub.bind(o.publish);
    } catch (const zmq::error_t& e) {
      Throw("fuse: cannot publish on '{}': {}", o.publish, e.what());
    }
  }

  // Where each frame's latency goes (system clocks only): per camera and frame, the node's
  // queue and work times and the message's arrival on this clock, until its group is decided.
  struct Timing {
    double queued_s = -1, process_s = -1, arrival_s = 0;
  };
  std::vector<std::map<long long, Timing>> timings(n);
  std::unique_ptr<FlightWorker> flight_worker;
  if (o.flights) {
    LiveFlightsOptions fopt = o.flight_options;
    fopt.analysis.ball_radius_m = 0.5 * o.ball_diameter_m;
    flight_worker = std::make_unique<FlightWorker>(fopt);
  }
  // Written beside --out and renamed at the end; a run that fails leaves no temporary file.
  AtomicOutput out_file(o.out);
  CsvWriter csv(out_file.temp_path(), BallCsvColumns(), 6);
  auto emit = [&](const SyncedFrame& group) {
    const BallFrame f = fusion.Fuse(group);
    ++summary.groups;
    // Capture to decision, for every frame fused (with a position or not).
    const double decided_s = SystemClockNow();
    const double latency_s = clock_kind == "system" ? decided_s - group.time_s : 0.0;
    if (clock_kind == "system") {
      summary.latency_s.push_back(latency_s);
      FuseSummary::LatencyParts parts;
      for (int c = 0; c < n; ++c) {
        if (!group.cameras[c]) continue;
        auto& t = timings[c];
        const auto it = t.find(group.cameras[c]->frame);
        if (it == t.end()) continue;
        const Timing& m = it->second;
        parts.queued_s = std::max(parts.queued_s, m.queued_s);
        parts.process_s = std::max(parts.process_s, m.process_s);
        parts.arrival_s = std::max(parts.arrival_s, m.arrival_s - group.cameras[c]->time_s);
        t.erase(t.begin(), std::next(it));
      }
      parts.pairing_s = latency_s - parts.arrival_s;
      summary.latency_parts.push_back(parts);
    }
    if (!f.result.ok()) return;
    const Eigen::Vector3d& p = f.result.point_world;
    csv << f.frame << f.time_s << p.x() << p.y() << p.z() << f.result.num_views()
        << f.result.rms_px;
    csv.EndRow();
    ++summary.rows_written;
    const BallMessage b{f.frame,         f.time_s, p.x(), p.y(), p.z(), f.result.num_views(),
                        f.result.rms_px, latency_s};
    if (pub) {
      const std::string topic = "ball";
      pub.send(zmq::buffer(topic), zmq::send_flags::sndmore | zmq::send_flags::dontwait);
      if (pub.send(zmq::buffer(Encode(b)), zmq::send_flags::dontwait)) ++summary.published;
    }
    if (flight_worker) {
      BallSample sample;
      sample.frame = f.frame;
      sample.time_s = f.time_s;
      sample.ball_in_world = p;
      sample.n_cams = f.result.num_views();
      sample.err_px = f.result.rms_px;
      flight_worker->Add(sample);
    }
  };
  auto publish_flights = [&] {
    if (!flight_worker) return;
    for (Flight& flight : flight_worker->Take()) {
      const FlightMessage m = ToMessage(flight, static_cast<long long>(summary.flights.size()));
      summary.flights.push_back(std::move(flight));
      if (!pub) continue;
      const std::string topic = "flight";
      pub.send(zmq::buffer(topic), zmq::send_flags::sndmore | zmq::send_flags::dontwait);
      if (pub.send(zmq::buffer(Encode(m)), zmq::send_flags::dontwait)) ++summary.flights_published;
    }
  };

  const auto start = std::chrono::steady_clock::now();
  double last_message = SteadyNow();
  double last_report = 0;
  std::vector<zmq::pollitem_t> items = {{router.handle(), 0, ZMQ_POLLIN, 0}};
  while (!StopRequested(o.control)) {
    try {
      zmq::poll(items, std::chrono::milliseconds(2));
    } catch (const zmq::error_t& e) {
      if (e.num() != EINTR) throw;
      continue;  // a signal (Ctrl-C, SIGTERM): StopRequested decides
    }
    zmq::message_t identity, payload;
    while (router.recv(identity, zmq::recv_flags::dontwait)) {
      const double t1 = SystemClockNow();
      const double arrival = SteadyNow();
      last_message = arrival;
      if (!identity.more() || !router.recv(payload, zmq::recv_flags::dontwait)) {
        ++summary.malformed;
        continue;
      }
      while (payload.more()) {  // extra parts: not our protocol
        zmq::message_t extra;
        if (!router.recv(extra, zmq::recv_flags::dontwait)) break;
        payload.rebuild(extra.data(), extra.size());
        ++summary.malformed;
      }
      ++summary.messages;
      Message m;
      try {
        m = Decode(payload.data(), payload.size());
      } catch (const MessageError& e) {
        switch (e.reason()) {
          case MessageError::Reason::kOversized:
            ++summary.oversized;
            break;
          case MessageError::Reason::kVersion:
            ++summary.wrong_version;
            break;
          case MessageError::Reason::kMalformed:
            ++summary.malformed;
            break;
        }
        continue;
      }
      // Every message but a pong or a ball names its camera and session.
      std::string camera, session;
      if (const auto* ping = std::get_if<PingMessage>(&m)) {
        PongMessage pong{ping->t0_s, t1, 0};
        pong.t2_s = SystemClockNow();
        router.send(identity, zmq::send_flags::sndmore | zmq::send_flags::dontwait);
        router.send(zmq::buffer(Encode(pong)), zmq::send_flags::dontwait);
        camera = ping->camera, session = ping->session;
      } else if (const auto* f = std::get_if<FrameMessage>(&m)) {
        camera = f->camera, session = f->session;
      } else if (const auto* k = std::get_if<SkipMessage>(&m)) {
        camera = k->camera, session = k->session;
      } else if (const auto* h = std::get_if<HelloMessage>(&m)) {
        camera = h->camera, session = h->session;
      } else if (const auto* b = std::get_if<ByeMessage>(&m)) {
        camera = b->camera, session = b->session;
      } else {
        ++summary.malformed;  // a pong or a ball message sent to us
        continue;
      }
      const auto it = index.find(camera);
      if (it == index.end()) {
        ++summary.unknown_camera;
        if (warned_unknown.insert(camera).second && warned_unknown.size() <= 10) {
          std::cerr << fmt::format("fuse: warning: messages from unknown camera '{}' ignored\n",
                                   camera);
        }
        continue;
      }
      const int c = it->second;
      if (sessions[c] != session) {
        if (!sessions[c].empty()) sync.Restart(c);
        sessions[c] = session;
        ++summary.cameras[c].sessions;
      }
      if (std::holds_alternative<PingMessage>(m) || std::holds_alternative<HelloMessage>(m)) {
        sync.Admit(c, arrival);  // connected: its frames are waited for
        continue;
      }
      if (std::holds_alternative<ByeMessage>(m)) {
        sync.EndOfStream(c);
        continue;
      }
      if (const auto* k = std::get_if<SkipMessage>(&m)) {
        if (k->clock != clock_kind && !clock_kind.empty()) continue;
        if (k->clock == "system" && !k->has_offset) continue;
        sync.SkipUntil(c, k->time_s + (k->clock == "system" ? k->offset_s : 0.0), arrival);
        continue;
      }
      const auto* f = std::get_if<FrameMessage>(&m);
      FuseCameraReport& r = summary.cameras[c];
      ++r.frames;
      if (clock_kind.empty()) clock_kind = f->clock;
      if (f->clock != clock_kind) {
        ++summary.clock_mismatch;
        continue;
      }
      CameraMessage cm;
      cm.camera = c;
      cm.frame = f->frame;
      cm.time_s = f->time_s;
      if (f->clock == "system") {
        if (!f->has_offset) {
          ++summary.unsynced;
          continue;
        }
        cm.time_s += f->offset_s;
        r.has_offset = true;
        r.offset_s = f->offset_s;
      }
      cm.candidates = f->candidates;
      if (f->clock == "system") {
        auto& t = timings[c];
        if (t.size() >= 1000) t.erase(t.begin());  // frames that never make a group
        t[cm.frame] = {f->queued_s, f->process_s, t1};
      }
      sync.Add(std::move(cm), arrival);
    }
    const double now = SteadyNow();
    while (auto group = sync.Next(now)) emit(*group);
    publish_flights();
    if (o.idle_exit_s > 0 && summary.messages > 0 && now - last_message > o.idle_exit_s) break;
    if (now - last_report > 0.5) {
      last_report = now;
      if (o.control != nullptr) {
        o.control->Report({"fuse", fusion.stats().frames, -1, "frames", ""});
      }
      if (o.progress) {
        std::cerr << fmt::format("\rfuse: {} frames, {} positions", fusion.stats().frames,
                                 summary.rows_written)
                  << std::flush;
      }
    }
  }
  if (o.progress) std::cerr << "\n";
  while (auto group = sync.Next(SteadyNow(), /*flush=*/true)) emit(*group);
  if (flight_worker) {
    flight_worker->Finish();
    publish_flights();
  }
  csv.Close();
  out_file.Commit();
  summary.fusion = fusion.stats();
  summary.sync = sync.stats();
  summary.sync_problems = sync.Problems(names);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace fv::net
