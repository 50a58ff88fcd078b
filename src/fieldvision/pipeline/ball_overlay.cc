#include "fieldvision/pipeline/ball_overlay.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <system_error>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/detect_video.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/io/video_writer.h"
#include "fieldvision/pipeline/detections_job.h"
#include "fieldvision/recon/ball_csv.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/strings.h"

namespace fv::pipeline {
namespace fs = std::filesystem;

namespace {

const cv::Scalar kCyan(255, 255, 0);

// BALL.csv's positions by frame (rows without a frame number or a finite position left out).
std::map<long long, Eigen::Vector3d> BallByFrame(const std::string& path) {
  const util::CsvTable table = util::CsvTable::Read(path);
  recon::CheckBallTrackRanges(table);
  std::map<long long, Eigen::Vector3d> balls;
  for (size_t r = 0; r < table.rows(); ++r) {
    const recon::BallSample s = recon::ReadBallCsvRow(table, r);
    if (s.frame >= 0 && s.ball_in_world.allFinite()) balls[s.frame] = s.ball_in_world;
  }
  return balls;
}

// A camera's accepted candidates by frame, as the detector's candidates (for DrawCandidates).
std::map<long long, std::vector<detect::BallCandidate>> CandidatesByFrame(const std::string& path,
                                                                          int camera) {
  std::map<long long, std::vector<detect::BallCandidate>> out;
  if (path.empty()) return out;
  const util::CsvTable table = util::CsvTable::Read(path);
  if (table.rows() == 0) return out;  // a camera that accepted nothing
  for (const CameraMessage& m : ParseDetections(table, camera, 2.0)) {
    for (const recon::BallObservation& o : m.candidates) {
      detect::BallCandidate c;
      c.centre_px = o.centre_px;
      c.radius_px = o.radius_px;
      c.score = o.score;
      c.accepted = true;
      out[m.frame].push_back(c);
    }
  }
  return out;
}

// The ball at `ball_in_world` drawn as the camera sees it: its projected centre and outline
// (the image of a point one radius off the line of sight gives the size). False when it is
// behind the camera or outside the image.
bool DrawBall(cv::Mat& bgr, const camera::Camera& camera, const Eigen::Vector3d& ball_in_world,
              double radius_m) {
  const std::optional<Eigen::Vector2d> c = camera.Project(ball_in_world);
  if (!c || !camera.InImage(*c)) return false;
  const Eigen::Vector3d sight = (ball_in_world - camera.CentreInWorld()).normalized();
  Eigen::Vector3d side = sight.cross(Eigen::Vector3d::UnitZ());
  if (side.squaredNorm() < 1e-12) side = sight.cross(Eigen::Vector3d::UnitX());
  const std::optional<Eigen::Vector2d> edge =
      camera.Project(ball_in_world + radius_m * side.normalized());
  const double r_px = std::min(edge ? (*edge - *c).norm() : 4.0, std::hypot(bgr.cols, bgr.rows));
  constexpr int kShift = 4;
  const auto pt = [](const Eigen::Vector2d& p) {
    return cv::Point(cvRound(p.x() * (1 << kShift)), cvRound(p.y() * (1 << kShift)));
  };
  cv::circle(bgr, pt(*c), cvRound(r_px * (1 << kShift)), kCyan, 1, cv::LINE_AA, kShift);
  const Eigen::Vector2d dx(r_px + 4, 0), dy(0, r_px + 4), gx(r_px + 1, 0), gy(0, r_px + 1);
  // Ticks outside the outline, so the candidates' marks inside stay visible.
  cv::line(bgr, pt(*c - dx), pt(*c - gx), kCyan, 1, cv::LINE_AA, kShift);
  cv::line(bgr, pt(*c + gx), pt(*c + dx), kCyan, 1, cv::LINE_AA, kShift);
  cv::line(bgr, pt(*c - dy), pt(*c - gy), kCyan, 1, cv::LINE_AA, kShift);
  cv::line(bgr, pt(*c + gy), pt(*c + dy), kCyan, 1, cv::LINE_AA, kShift);
  return true;
}

void FrameLabel(cv::Mat& bgr, const std::string& text) {
  const cv::Point org(8, 22);
  cv::putText(bgr, text, org, cv::FONT_HERSHEY_SIMPLEX, 0.6, {0, 0, 0}, 3, cv::LINE_AA);
  cv::putText(bgr, text, org, cv::FONT_HERSHEY_SIMPLEX, 0.6, {255, 255, 255}, 1, cv::LINE_AA);
}

}  // namespace

std::vector<std::string> DrawNames(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  std::set<std::string> taken;
  for (size_t i = 0; i < names.size(); ++i) {
    std::string name = util::FileNamePart(names[i]);
    if (name.empty()) name = fmt::format("cam{}", i + 1);
    std::string unique = name;
    for (int k = 2; !taken.insert(unique).second; ++k) unique = fmt::format("{}-{}", name, k);
    out.push_back(unique);
  }
  return out;
}

void BallOverlayOptions::Check() const {
  FV_REQUIRE(!dir.empty(), "--draw needs a folder");
  FV_REQUIRE(std::isfinite(ball_diameter_m) && ball_diameter_m > 0,
             "ball_diameter_m must be > 0 (got {})", ball_diameter_m);
  FV_REQUIRE(std::isfinite(fps) && fps >= 0, "--fps must be >= 0 (got {})", fps);
}

std::string BallOverlayResult::Summary() const {
  std::string s =
      fmt::format("drew {} camera frames, the 3D ball in {} of them:", frames, balls_drawn);
  for (const std::string& v : videos) s += " " + v;
  return s;
}

BallOverlayResult DrawBallOverlays(const std::vector<camera::Camera>& cameras,
                                   const std::vector<std::string>& videos,
                                   const std::string& ball_csv,
                                   const std::vector<std::string>& detections,
                                   const BallOverlayOptions& o) {
  o.Check();
  FV_REQUIRE(cameras.size() == videos.size(), "--draw: {} cameras but {} videos", cameras.size(),
             videos.size());
  FV_REQUIRE(detections.empty() || detections.size() == cameras.size(),
             "--draw: {} cameras but {} detection files", cameras.size(), detections.size());
  FV_REQUIRE(o.names.empty() || o.names.size() == cameras.size(), "--draw: {} cameras but {} names",
             cameras.size(), o.names.size());
  std::vector<std::string> names = o.names;
  if (names.empty()) {
    for (const camera::Camera& cam : cameras) names.push_back(cam.name);
    names = DrawNames(names);
  }
  const std::map<long long, Eigen::Vector3d> balls = BallByFrame(ball_csv);
  std::error_code ec;
  FV_REQUIRE(fs::is_directory(o.dir, ec), "--draw: '{}' is not a folder", o.dir);
  const std::string legend =
      "cyan: the ball's 3D position (BALL.csv) seen from this camera, at its size; green: this "
      "camera's accepted candidates (score)";
  BallOverlayResult result;
  util::Progress progress("draw", -1, "camera frames", o.progress);
  for (size_t i = 0; i < cameras.size(); ++i) {
    const camera::Camera& cam = cameras[i];
    const auto candidates =
        CandidatesByFrame(detections.empty() ? "" : detections[i], static_cast<int>(i));
    io::VideoSourceOptions vo;
    vo.fps = o.fps;
    auto source = io::VideoSource::Open(videos[i], vo);
    FV_REQUIRE(!source->live(), "--draw: '{}' is a live source (its frames now are not the run's)",
               videos[i]);
    const cv::Mat band = detect::TextBand({legend}, source->width());
    const std::string& name = names[i];
    io::PlayableVideoWriter writer(fmt::format("{}/{}.mp4", o.dir, name),
                                   source->fps() > 0 ? source->fps() : 30.0,
                                   {source->width(), source->height() + band.rows});
    io::Frame f;
    while ((o.max_frames <= 0 || source->frames_read() < o.max_frames) && source->Read(f)) {
      cv::Mat img = f.bgr.clone();
      const auto cands = candidates.find(f.index);
      if (cands != candidates.end()) detect::DrawCandidates(img, cands->second);
      const auto ball = balls.find(f.index);
      if (ball != balls.end() && DrawBall(img, cam, ball->second, 0.5 * o.ball_diameter_m)) {
        ++result.balls_drawn;
      }
      FrameLabel(img, fmt::format("{}  frame {}", name, f.index));
      cv::vconcat(img, band, img);
      writer.Write(img);
      progress.Update(++result.frames);
    }
    writer.Close();
    result.videos.push_back(writer.path());
  }
  progress.Finish();
  return result;
}

}  // namespace fv::pipeline
