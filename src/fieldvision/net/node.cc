#include "fieldvision/net/node.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <iostream>
#include <limits>
#include <mutex>
#include <optional>
#include <random>
#include <thread>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <zmq.hpp>

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/detect/ball_detector.h"
#include "fieldvision/detect/camera_background.h"
#include "fieldvision/field/field.h"
#include "fieldvision/io/frame_source.h"
#include "fieldvision/net/clock_sync.h"
#include "fieldvision/net/messages.h"
#include "fieldvision/pipeline/ball_job.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/strings.h"

namespace fv::net {

void NodeOptions::Check() const {
  FV_REQUIRE(!camera.empty(), "node: --camera is required");
  FV_REQUIRE(!video.empty(), "node: --video is required");
  FV_REQUIRE(util::StartsWith(connect, "tcp://") || util::StartsWith(connect, "ipc://"),
             "node: --connect must be tcp://HOST:PORT (got '{}')", connect);
  FV_REQUIRE(std::isfinite(ball_diameter_m) && ball_diameter_m > 0 && ball_diameter_m < 2,
             "node: --ball-diameter must be in (0, 2) metres (got {})", ball_diameter_m);
  FV_REQUIRE(std::isfinite(start_at_s) && start_at_s >= 0, "node: --start-at must be >= 0");
  FV_REQUIRE(std::isfinite(fps) && fps >= 0 && fps <= 100000,
             "node: --fps must be a frame rate in (0, 100000] (got {})", fps);
  FV_REQUIRE(live_buffer_frames >= 1, "node: --live-buffer must be >= 1");
  FV_REQUIRE(max_frames >= 0, "node: --max-frames must be >= 0");
  FV_REQUIRE(std::isfinite(connect_wait_s) && connect_wait_s >= 0,
             "node: --connect-wait must be >= 0");
  FV_REQUIRE(std::isfinite(ping_interval_s) && ping_interval_s > 0,
             "node: ping interval must be > 0");
  FV_REQUIRE(std::isfinite(clock_offset_s) && std::abs(clock_offset_s) < 1e6,
             "node: --clock-offset must be finite");
  track.Check();
}

std::string NodeSummary::ToString() const {
  std::string s = fmt::format(
      "node {}: {} frames ({} times), {} sent, {} not sent (fusion node unreachable or slow), "
      "{} skipped by the source (node slower than the camera)",
      camera, frames, source_origin.empty() ? "no" : source_origin, sent, send_dropped,
      source_dropped);
  if (!camera_note.empty()) s += "\n" + camera_note;
  if (has_offset) {
    s += fmt::format(
        "\nclock: fusion node - this node = {:+.4f} s (round trip {:.2f} ms, {} samples)", offset_s,
        1e3 * round_trip_s, clock_samples);
  } else {
    s += "\nclock: no reply from the fusion node";
  }
  if (stage.window_scans > 0) {
    s += fmt::format(
        "\n{} frames searched in a window around the ball ({} and a band of rows), {} whole",
        stage.window_scans, stage.band_scans, stage.full_scans);
  }
  if (stage.bad_frames > 0) {
    s += fmt::format("\n{} frames could not be decoded (first: {})", stage.bad_frames,
                     stage.first_bad_frame);
  }
  if (frames > 0) {
    s += fmt::format(
        "\nwork per frame (decoding, detection): p50 {:.1f} ms, p95 {:.1f} ms, max {:.1f} ms",
        1e3 * process_p50_s, 1e3 * process_p95_s, 1e3 * process_max_s);
  }
  if (in_step_frames > 0) {
    s += fmt::format("\nin step with the fusion node ({} frames waited for its decision{})",
                     in_step_frames, in_step_to_end ? "" : ", then alone");
  }
  if (hints > 0) {
    s += fmt::format("\n{} ball positions from the fusion node (hints), {} balls fitted there",
                     hints, stage.guided);
  }
  if (bad_replies > 0) s += fmt::format("\n{} bad replies ignored", bad_replies);
  s += fmt::format("\n{:.2f} s", seconds);
  return s;
}

namespace {

// The kind of a message handed to the link thread (its first byte).
constexpr char kFrameTag = 'f', kOtherTag = 'o';

// In step with the fusion node (a file read as fast as it can be): the longest wait for its
// decision of a frame before going on alone (longer than fuse's longest media wait, 9 s).
constexpr double kStepWaitS = 10.0;

// How long a fusion node may ignore a node for now (a second node of its camera, while the
// first goes on; it gives way after 1.5 s of quiet, or once it has read the first one's bye
// behind its queued frames) before the node stops.
constexpr double kRefusedForNowS = 10.0;

std::string NewSession() {
  std::random_device rd;
  return fmt::format("{:08x}{:08x}", rd(), rd());
}

// The socket side of a node, in its own thread: forwards what the main thread sends over an
// inproc pair, pings the fusion node and keeps the clock estimate.
class NodeLink {
 public:
  // `hints`: where the fusion node's hints go (null: ignored); `system_clock`: frame times are
  // this machine's clock (else the recording's, as the fusion node's).
  // `image_size`, `fps`: the source's, told in the hello (the fusion node checks the size).
  NodeLink(zmq::context_t& ctx, const NodeOptions& o, std::string camera, std::string session,
           pipeline::BallHintBoard* hints, bool system_clock, cv::Size image_size, double fps)
      : ctx_(ctx),
        o_(o),
        camera_(std::move(camera)),
        session_(std::move(session)),
        hints_(hints),
        system_clock_(system_clock),
        image_size_(image_size),
        fps_(std::isfinite(fps) && fps > 0 ? fps : 0.0) {
    // Bind the pair before the thread connects to it (inproc needs the bind first).
    to_link_ = zmq::socket_t(ctx_, zmq::socket_type::pair);
    to_link_.set(zmq::sockopt::sndhwm, 64);
    to_link_.set(zmq::sockopt::linger, 0);
    to_link_.bind("inproc://node-link");
    thread_ = std::thread([this] { Run(); });
  }
  ~NodeLink() {
    try {
      Finish();
    } catch (const std::exception&) {  // a socket error while unwinding: the thread is gone
    }
  }

  // From the main thread: a message for the fusion node (`frame`: a frame message, whose drops
  // the link counts); false when dropped here (link busy). A tag byte before the message says
  // which kind it is.
  bool Send(const std::string& bytes, bool frame) {
    const std::string tagged = (frame ? kFrameTag : kOtherTag) + bytes;
    return to_link_.send(zmq::buffer(tagged), zmq::send_flags::dontwait).has_value();
  }
  // Sends the bye message, stops the thread (waiting at most ~1 s for the bye to leave).
  void Finish() {
    if (!thread_.joinable()) return;
    const std::string end = "end";
    to_link_.send(zmq::buffer(end), zmq::send_flags::none);
    thread_.join();
    to_link_.close();
  }
  double Now() const { return io::SystemClockNow() + o_.clock_offset_s; }
  bool has_offset() const { return has_offset_; }
  double offset_s() const { return offset_s_; }
  std::atomic<long long> send_dropped{0};  // frame messages the socket could not take
  std::atomic<long long> bad_replies{0};
  std::atomic<int> samples{0};
  std::atomic<double> round_trip_s{0};
  std::atomic<long long> frames_for_bye{0};  // set by the main thread before Finish
  std::atomic<long long> hints_used{0};

 private:
  void SetRefusal(const PongMessage& pong) {
    std::lock_guard<std::mutex> lock(refusal_mutex_);
    if (pong.refused.empty()) {
      refusal_.clear();
      return;
    }
    if (refusal_.empty()) {
      refused_since_ = std::chrono::steady_clock::now();
      if (pong.refused_for_now) {
        std::cerr << fmt::format("node {}: the fusion node ignores this node for now: {}\n",
                                 camera_, pong.refused);
      }
    }
    refusal_ = pong.refused;
    refusal_for_now_ = pong.refused_for_now;
  }

  // A fusion node's hint, on this node's frame clock, to the camera stage's board.
  void TakeHint(const HintMessage& h) {
    if (hints_ == nullptr) return;
    double time_s = h.time_s;
    if (system_clock_) {
      if (!has_offset_) return;
      time_s -= offset_s_ + o_.clock_offset_s;  // fuse clock -> this node's frame clock
    }
    {
      std::lock_guard<std::mutex> lock(decided_mutex_);
      decided_s_ = std::max(decided_s_, time_s);
    }
    decided_changed_.notify_all();
    if (h.lost) {  // the fusion tells of frames without a position: unconfirmed scans apply
      hints_->MarkTellsLoss();
      return;
    }
    hints_->Publish(time_s, Eigen::Vector3d(h.x_m, h.y_m, h.z_m), h.radius_m);
    ++hints_used;
  }

 public:
  // Whether the fusion node said (in its clock replies) that it sends a hint for every frame.
  bool fuse_sends_hints() const { return fuse_hints_; }
  // Why the fusion node ignores this node, "" while it does not: at once when it never will
  // hear it (an unknown camera, another image size), else once its latest replies have said so
  // for longer than `for_now_s` (a second node of one camera; the first may end).
  std::string Refusal(double for_now_s) const {
    std::lock_guard<std::mutex> lock(refusal_mutex_);
    if (refusal_.empty()) return "";
    if (refusal_for_now_ && std::chrono::steady_clock::now() - refused_since_ <
                                std::chrono::duration<double>(for_now_s)) {
      return "";
    }
    return refusal_;
  }
  // Waits until the fusion node has decided the frame at `time_s` (on this node's frame clock:
  // a hint of that time or later came), at most `timeout_s`; false when it did not.
  bool WaitForDecision(double time_s, double timeout_s, const pipeline::JobControl* control) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    std::unique_lock<std::mutex> lock(decided_mutex_);
    while (decided_s_ < time_s - 1e-6) {
      if (std::chrono::steady_clock::now() >= until || StopRequested(control)) return false;
      decided_changed_.wait_for(lock, std::chrono::milliseconds(50));
    }
    return true;
  }

 private:
  void Run() {
    zmq::socket_t from_main(ctx_, zmq::socket_type::pair);
    from_main.connect("inproc://node-link");
    zmq::socket_t dealer(ctx_, zmq::socket_type::dealer);
    dealer.set(zmq::sockopt::linger, 1000);
    dealer.set(zmq::sockopt::sndhwm, 256);
    dealer.set(zmq::sockopt::immediate, 1);  // no queue for a fusion node that is not there
    dealer.set(zmq::sockopt::reconnect_ivl, 100);
    dealer.set(zmq::sockopt::reconnect_ivl_max, 1000);
    dealer.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(kMaxMessageBytes));
    dealer.connect(o_.connect);
    ClockSync clock;
    int pings = 0;
    double next_ping = Now();
    std::vector<zmq::pollitem_t> items = {{from_main.handle(), 0, ZMQ_POLLIN, 0},
                                          {dealer.handle(), 0, ZMQ_POLLIN, 0}};
    for (;;) {
      const double wait_s = std::max(0.0, next_ping - Now());
      zmq::poll(items, std::chrono::milliseconds(static_cast<int>(std::ceil(wait_s * 1000))));
      if (items[1].revents & ZMQ_POLLIN) {
        zmq::message_t reply;
        while (dealer.recv(reply, zmq::recv_flags::dontwait)) {
          const double t3 = Now();
          try {
            const Message m = Decode(reply.data(), reply.size());
            if (const auto* pong = std::get_if<PongMessage>(&m)) {
              fuse_hints_ = pong->hints;
              SetRefusal(*pong);
              if (clock.Add(pong->t0_s, pong->t1_s, pong->t2_s, t3)) {
                const ClockSample e = *clock.Estimate();
                offset_s_ = e.offset_s;
                round_trip_s = e.round_trip_s;
                samples = clock.samples();
                has_offset_ = true;
              }
            } else if (const auto* hint = std::get_if<HintMessage>(&m)) {
              TakeHint(*hint);
            }
          } catch (const Error&) {
            ++bad_replies;
          }
        }
      }
      if (items[0].revents & ZMQ_POLLIN) {
        zmq::message_t msg;
        bool end = false;
        while (from_main.recv(msg, zmq::recv_flags::dontwait)) {
          const std::string_view tagged = msg.to_string_view();
          if (tagged == "end") {
            end = true;
            break;
          }
          if (tagged.empty()) continue;
          const bool frame = tagged.front() == kFrameTag;
          if (!dealer.send(zmq::buffer(tagged.substr(1)), zmq::send_flags::dontwait) && frame) {
            ++send_dropped;
          }
        }
        if (end) {
          ByeMessage bye{camera_, session_, frames_for_bye};
          dealer.send(zmq::buffer(Encode(bye)), zmq::send_flags::dontwait);
          return;
        }
      }
      if (Now() >= next_ping) {
        // With every ping: a fusion node that refused this session at first (its earlier node
        // not yet quiet) or restarted learns its size and rate all the same.
        const HelloMessage h{camera_,
                             session_,
                             image_size_.width,
                             image_size_.height,
                             fps_,
                             o_.video,
                             system_clock_ ? "system" : "media"};
        dealer.send(zmq::buffer(Encode(h)), zmq::send_flags::dontwait);
        PingMessage p{camera_, session_, Now()};
        dealer.send(zmq::buffer(Encode(p)), zmq::send_flags::dontwait);
        ++pings;
        // A burst of 8 pings 20 ms apart first (a quick estimate), then the steady rate.
        next_ping = Now() + (pings < 8 ? 0.02 : o_.ping_interval_s);
      }
    }
  }

  zmq::context_t& ctx_;
  const NodeOptions& o_;
  std::string camera_, session_;
  zmq::socket_t to_link_;
  std::thread thread_;
  pipeline::BallHintBoard* hints_;
  bool system_clock_;
  cv::Size image_size_;
  double fps_;
  std::atomic<bool> fuse_hints_{false};
  mutable std::mutex refusal_mutex_;
  std::string refusal_;  // from the latest clock reply
  bool refusal_for_now_ = false;
  std::chrono::steady_clock::time_point refused_since_;
  std::mutex decided_mutex_;
  std::condition_variable decided_changed_;
  double decided_s_ = -std::numeric_limits<double>::infinity();  // the latest hint's time
  std::atomic<bool> has_offset_{false};
  std::atomic<double> offset_s_{0};
};

// A blank grass-coloured frame with discs of the preset ball colours, so that candidates go
// through every stage of the detector; JPEG-encoded for an encoded source.
io::SourceFrame WarmUpFrame(cv::Size size, bool encoded) {
  io::SourceFrame blank;
  blank.bgr = cv::Mat(size, CV_8UC3, cv::Scalar(90, 120, 90));
  const cv::Scalar colours[] = {{0, 110, 255}, {0, 230, 255}, {255, 255, 255}, {180, 105, 255},
                                {0, 0, 230},   {230, 60, 0},  {0, 200, 0},     {10, 10, 10}};
  const int r = std::max(4, std::min(size.width, size.height) / 30);
  for (int i = 0; i < 8; ++i) {
    const cv::Point centre((2 * i + 1) * size.width / 16, size.height / 2);
    cv::circle(blank.bgr, centre, r, colours[i], cv::FILLED, cv::LINE_AA);
  }
  if (encoded) {
    codecs::ImEncode(".jpg", blank.bgr, &blank.jpeg);
    blank.bgr = cv::Mat();
  }
  return blank;
}

// A file read as fast as it can be goes in step with the fusion node, as `ball` does
// (ball_hints.h): frame k waits until the fusion decided frame k - lag, so that its hints arrive
// in time to be used (else the node is through the file before the first one comes). Without a
// decision for kStepWaitS it goes on alone, saying so.
class InStep {
 public:
  // `on`: the node may go in step (a file read as fast as it can be, hints used); it does while
  // the fusion node says it sends hints (its clock replies; a fusion node started later says so
  // later).
  InStep(bool on, std::string camera) : on_(on), camera_(std::move(camera)) {}
  bool on() const { return on_; }
  // Before a frame's work.
  void Wait(NodeLink& link, const pipeline::JobControl* control, NodeSummary& summary) {
    if (!on_ || !link.fuse_sends_hints() || static_cast<int>(sent_s_.size()) < lag_) return;
    if (link.WaitForDecision(sent_s_.front(), kStepWaitS, control)) {
      ++summary.in_step_frames;
    } else if (!StopRequested(control)) {
      on_ = false;
      std::cerr << fmt::format(
          "node {}: no hint from the fusion node for {:.0f} s: going on without waiting\n", camera_,
          kStepWaitS);
    }
  }
  // A frame at `time_s` was sent.
  void Sent(double time_s) {
    sent_s_.push_back(time_s);
    if (static_cast<int>(sent_s_.size()) > lag_) sent_s_.pop_front();
  }

 private:
  bool on_;
  std::string camera_;
  const int lag_ = pipeline::BallHintOptions().lag_messages;
  std::deque<double> sent_s_;  // times of the last `lag_` frames sent
};

// Waits for the first clock reply (at most connect_wait_s) so that the first frames can be
// placed in time.
void WaitForClock(const NodeLink& link, const NodeOptions& o) {
  const auto wait_until =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(o.connect_wait_s);
  while (!link.has_offset() && std::chrono::steady_clock::now() < wait_until &&
         !StopRequested(o.control)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// The median, 95th percentile and largest work time per frame.
void SetProcessTimes(const std::vector<double>& process_s, NodeSummary& summary) {
  if (process_s.empty()) return;
  summary.process_p50_s = util::NearestRankPercentile(process_s, 0.5);
  summary.process_p95_s = util::NearestRankPercentile(process_s, 0.95);
  summary.process_max_s = *std::max_element(process_s.begin(), process_s.end());
}

// The link's counts and clock after it finished.
void AddLinkSummary(const NodeLink& link, NodeSummary& summary) {
  summary.send_dropped += link.send_dropped;
  summary.sent -= link.send_dropped;
  summary.bad_replies = link.bad_replies;
  summary.has_offset = link.has_offset();
  summary.offset_s = link.offset_s();
  summary.round_trip_s = link.round_trip_s;
  summary.clock_samples = link.samples;
  summary.hints = link.hints_used;
}

// The node's video, its camera fitted to it (camera_note): times from the video, never assumed (the
// fusion node pairs cameras by them).
std::unique_ptr<io::FrameSource> OpenNodeSource(const NodeOptions& o, camera::Camera& camera,
                                                std::string& camera_note) {
  io::FrameSourceOptions so;
  so.encoded = true;  // MJPG / JPEG: decoded only around the tracked ball
  so.realtime = o.realtime;
  so.start_at_s = o.start_at_s;
  so.live_buffer_frames = o.live_buffer_frames;
  so.fps = o.fps;
  auto source = io::OpenFrameSource(o.video, so);
  FV_REQUIRE(source->rate_known(),
             "video '{}' has no frame rate of its own (an image sequence, or a container without "
             "one): give --fps",
             o.video);
  camera_note = io::FitCameraToSource(*source, camera, o.camera);
  return source;
}

}  // namespace

NodeSummary RunNode(const NodeOptions& o) {
  o.Check();
  camera::Camera camera = pipeline::ReadRigCamera(o.camera);
  std::optional<field::FieldModel> field;
  if (!o.field.empty()) field = field::LoadField(o.field);
  std::string camera_note;
  const std::unique_ptr<io::FrameSource> source = OpenNodeSource(o, camera, camera_note);
  const cv::Size size = source->FrameSize();
  const detect::BallDetectorOptions dopt =
      pipeline::TrackingDetectorOptions(o.ball_diameter_m, o.colour);
  auto detector = std::make_shared<detect::BallDetector>(dopt, &camera, field ? &*field : nullptr);
  const auto background = detect::UseCameraBackground(
      o.background && o.detect && !o.realtime && !source->live() && source->FrameCount() > 0,
      o.video, &camera, detector.get());
  if (background) background->Start();
  pipeline::CameraStage stage(0, camera, pipeline::BallDetectFnFor(detector), o.track, o.video,
                              pipeline::BallGuidedFnFor(detector));
  if (o.detect) {
    // The first detection pays for lazy set-up (OpenCV, the decoder, page faults: ~1 s on a
    // loaded machine); pay it on a blank frame before the stream starts, not on its first frames.
    pipeline::CameraStage(0, camera, pipeline::BallDetectFnFor(detector), o.track, "warm-up frame")
        .Process(WarmUpFrame(size, source->encoded()));
  }

  std::optional<pipeline::BallHintBoard> hints;
  if (o.hints && o.detect) {
    hints.emplace(1, pipeline::BallHintOptions(), /*wait=*/false);
    // Positions arrive while the fusion node has one, lost hints when it has none, and nothing
    // at all when its hints are off: their absence alone says nothing (the unconfirmed
    // whole-frame searches start with the first lost hint).
    stage.SetHints(&*hints, /*no_hint_means_unconfirmed=*/false);
  }

  NodeSummary summary;
  summary.camera = camera.name;
  summary.camera_note = camera_note;
  const auto start = std::chrono::steady_clock::now();
  zmq::context_t ctx(1);
  const std::string session = NewSession();
  {
    const bool system_clock = source->live();
    NodeLink link(ctx, o, camera.name, session, hints ? &*hints : nullptr, system_clock, size,
                  source->fps());
    WaitForClock(link, o);
    util::Progress progress("node " + camera.name,
                            o.max_frames > 0 ? o.max_frames : source->FrameCount(), "frames",
                            o.progress);
    io::SourceFrame in;
    FrameMessage m;
    m.camera = camera.name;
    m.session = session;
    m.clock = system_clock ? "system" : "media";
    std::vector<double> process_s;
    long long last_dropped = 0;
    InStep step(hints && !system_clock, camera.name);
    std::string refusal;
    while (!StopRequested(o.control) && (o.max_frames == 0 || summary.frames < o.max_frames) &&
           (refusal = link.Refusal(kRefusedForNowS)).empty() && source->ReadFrame(&in)) {
      const double read_s = io::SystemClockNow();
      if (const long long dropped = source->dropped(); dropped > last_dropped) {
        // Tell the fusion node now, before the work on this frame, that the skipped frames will
        // not come, so that it pairs the other cameras' frames without waiting for them.
        SkipMessage skip{camera.name, session,         in.frame,          m.time_s,
                         m.clock,     link.offset_s(), link.has_offset(), dropped - last_dropped};
        skip.time_s = system_clock ? in.time_s + o.clock_offset_s : in.time_s;
        link.Send(Encode(skip), /*frame=*/false);
        last_dropped = dropped;
      }
      step.Wait(link, o.control, summary);
      pipeline::CameraMessage cm;
      if (o.detect) {
        cm = stage.Process(in);
      } else {
        cm.frame = in.frame;
        cm.time_s = in.time_s;
      }
      m.process_s = std::max(0.0, io::SystemClockNow() - read_s);
      m.queued_s = system_clock ? std::clamp(read_s - in.time_s, 0.0, 3599.0) : -1.0;
      process_s.push_back(m.process_s);
      ++summary.frames;
      summary.source_origin = ToString(in.origin);
      m.frame = cm.frame;
      // Live times are on this machine's system clock, which the node's clock offset shifts.
      m.time_s = system_clock ? cm.time_s + o.clock_offset_s : cm.time_s;
      m.origin = ToString(in.origin);
      m.has_offset = link.has_offset();
      m.offset_s = link.offset_s();
      m.candidates = std::move(cm.candidates);
      step.Sent(cm.time_s);
      if (link.Send(Encode(m), /*frame=*/true)) {
        ++summary.sent;
      } else {
        ++summary.send_dropped;
      }
      progress.Update(summary.frames);
      if (o.control != nullptr) {
        o.control->Report({"node", summary.frames, source->FrameCount(), "frames", ""});
      }
    }
    progress.Finish();
    summary.in_step_to_end = step.on() && summary.in_step_frames > 0;
    SetProcessTimes(process_s, summary);
    link.frames_for_bye = summary.frames;
    if (refusal.empty()) refusal = link.Refusal(0);  // a file read before the reply came
    link.Finish();
    AddLinkSummary(link, summary);
    FV_REQUIRE(refusal.empty(), "node {}: the fusion node at {} refuses its frames: {}",
               camera.name, o.connect, refusal);
  }
  summary.source_dropped = source->dropped();
  summary.stage = stage.stats();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace fv::net
