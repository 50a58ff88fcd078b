#include "fieldvision/detect/detect_video.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/codecs/codecs.h"
#include "fieldvision/detect/camera_background.h"
#include "fieldvision/field/field_draw.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/io/video_writer.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/strings.h"

namespace fv::detect {
namespace {

// The field's far edge the off-field check used (BallDetector::OffFieldBoundary), labelled.
void DrawFieldBoundary(cv::Mat& bgr, const FieldBoundary& boundary) {
  if (!boundary.valid()) return;
  std::vector<cv::Point> line;
  for (int x = 0; x < bgr.cols; x += 4) {
    line.emplace_back(x, cvRound(boundary.RowAt(x + 0.5)));
  }
  line.emplace_back(bgr.cols - 1, cvRound(boundary.RowAt(bgr.cols - 0.5)));
  const cv::Scalar magenta(255, 0, 255);
  cv::polylines(bgr, line, false, magenta, 1, cv::LINE_AA);
  cv::putText(bgr, "field edge", line.front() + cv::Point(4, -4), cv::FONT_HERSHEY_SIMPLEX, 0.4,
              magenta, 1, cv::LINE_AA);
}

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.45;
constexpr int kLineHeight = 18;

// `lines` (already wrapped) in white on a black band `width` px wide.
cv::Mat Band(const std::vector<std::string>& lines, int width) {
  cv::Mat band(kLineHeight * static_cast<int>(lines.size()) + 6, width, CV_8UC3,
               cv::Scalar::all(0));
  for (size_t i = 0; i < lines.size(); ++i) {
    cv::putText(band, lines[i], cv::Point(4, kLineHeight * static_cast<int>(i + 1)), kFont,
                kFontScale, cv::Scalar::all(255), 1, cv::LINE_AA);
  }
  return band;
}

}  // namespace

cv::Mat TextBand(const std::vector<std::string>& text, int width) {
  std::vector<std::string> lines;
  for (const std::string& t : text) {
    for (std::string& line : field::WrapText(t, width - 8, kFontScale)) {
      lines.push_back(std::move(line));
    }
  }
  return Band(lines, width);
}

cv::Mat CandidateLegend(int width) {
  return TextBand({"green: accepted candidate (score; the first-ranked, the ball, drawn thick and "
                   "marked #1); red: rejected; magenta: the field's far edge (above it a higher "
                   "score is needed)"},
                  width);
}

void DetectVideoOptions::Check() const {
  FV_REQUIRE(!video.empty(), "--video is required");
  FV_REQUIRE(!out.empty(), "--out is required");
  FV_REQUIRE(max_frames == -1 || max_frames > 0, "max_frames must be -1 or > 0 (got {})",
             max_frames);
  detector.Check();
  dnn.Check();
}

std::string DetectVideoResult::Summary() const {
  return fmt::format("{} frames, {} candidates, ball accepted in {} frames, {:.1f} frames/s{}{}",
                     frames, candidates, frames_with_ball, seconds > 0 ? frames / seconds : 0.0,
                     background.empty() ? "" : "\n" + background,
                     frames_note.empty() ? "" : "\n" + frames_note);
}

void DrawCandidates(cv::Mat& bgr, const std::vector<BallCandidate>& candidates) {
  constexpr int kShift = 4;  // sub-pixel drawing
  const auto pt = [](const Eigen::Vector2d& p) {
    return cv::Point(cvRound(p.x() * (1 << kShift)), cvRound(p.y() * (1 << kShift)));
  };
  // Candidates come best first: the first accepted one is the frame's ball.
  const auto first = std::find_if(candidates.begin(), candidates.end(),
                                  [](const BallCandidate& c) { return c.accepted; });
  for (auto it = candidates.rbegin(); it != candidates.rend(); ++it) {
    const BallCandidate& c = *it;
    const int r = cvRound(std::max(c.radius_px, 1.0) * (1 << kShift));
    if (c.accepted) {
      const cv::Scalar green(0, 255, 0);
      const bool ball = &c == &*first;
      const int thick = ball ? 2 : 1;
      cv::circle(bgr, pt(c.centre_px), r, green, thick, cv::LINE_AA, kShift);
      const Eigen::Vector2d dx(3, 0), dy(0, 3);
      cv::line(bgr, pt(c.centre_px - dx), pt(c.centre_px + dx), green, 1, cv::LINE_AA, kShift);
      cv::line(bgr, pt(c.centre_px - dy), pt(c.centre_px + dy), green, 1, cv::LINE_AA, kShift);
      cv::putText(bgr, fmt::format("{}{:.2f}", ball ? "#1 " : "", c.score),
                  cv::Point(cvRound(c.centre_px.x() + c.radius_px + 4), cvRound(c.centre_px.y())),
                  cv::FONT_HERSHEY_SIMPLEX, 0.45, green, 1, cv::LINE_AA);
    } else {
      cv::circle(bgr, pt(c.centre_px), r, cv::Scalar(0, 0, 255), 1, cv::LINE_AA, kShift);
    }
  }
}

DetectVideoResult DetectVideo(const DetectVideoOptions& o) {
  o.Check();
  std::optional<camera::Camera> camera;
  if (!o.camera.empty()) camera = camera::ReadCameraYaml(o.camera);
  std::optional<field::FieldModel> field;
  if (!o.field.empty()) field = field::LoadField(o.field);
  auto source = io::VideoSource::Open(o.video);
  const std::string camera_note = camera ? source->FitCamera(*camera, o.camera) : "";
  AnyBallDetector detector(o.detector, o.dnn, camera ? &*camera : nullptr,
                           field ? &*field : nullptr);
  const auto background =
      UseCameraBackground(o.background, o.video, camera ? &*camera : nullptr, &detector);
  // Written beside --out and renamed over it at the end: a failed run leaves the old file.
  util::AtomicOutput out_file(o.out);
  util::CsvWriter csv(out_file.temp_path(),
                      {"frame", "u", "v", "radius_px", "score", "accepted", "sigma_px"});
  const long long total = o.max_frames > 0 && source->frame_count() > 0
                              ? std::min(o.max_frames, source->frame_count())
                              : (o.max_frames > 0 ? o.max_frames : source->frame_count());
  std::optional<io::PlayableVideoWriter> writer;  // renamed over --draw at the end
  std::string draw_dir;
  std::string draw_image;  // one image drawn (a still's --draw x.jpg)
  cv::Mat legend;          // below each drawn frame, made again only for a frame of another width
  if (!o.draw.empty()) {
    legend = CandidateLegend(source->width());
    if (io::IsVideoName(o.draw)) {
      const double fps = source->fps() > 0 ? source->fps() : 30.0;
      // The frame and, below it, the legend.
      writer.emplace(o.draw, fps, cv::Size(source->width(), source->height() + legend.rows),
                     "--draw");
    } else if (io::IsImageFile(o.draw)) {
      // A name such as x.jpg made a folder of that name: one image is written for one frame.
      FV_REQUIRE(total == 1,
                 "--draw '{}' names one image but {} frames of '{}' are read: give a video (.mp4, "
                 ".avi, .mkv), a folder for a JPEG a frame, or --max-frames 1",
                 o.draw, total > 0 ? std::to_string(total) : "several", o.video);
      draw_image = o.draw;
    } else {
      std::error_code ec;
      std::filesystem::create_directories(o.draw, ec);
      FV_REQUIRE(std::filesystem::is_directory(o.draw), "cannot create folder '{}' for --draw",
                 o.draw);
      draw_dir = o.draw;
    }
  }
  DetectVideoResult result;
  if (o.on_start) o.on_start();
  util::Progress progress("detect", total, "frames", o.progress);
  const auto t0 = std::chrono::steady_clock::now();
  io::Frame frame;
  while ((o.max_frames < 0 || result.frames < o.max_frames) && source->Read(frame)) {
    const auto cands = detector.Detect(frame.bgr);
    bool any = false;
    for (const auto& c : cands) {
      csv << frame.index << c.centre_px.x() << c.centre_px.y() << c.radius_px << c.score
          << (c.accepted ? 1 : 0) << c.sigma_px;
      csv.EndRow();
      any = any || c.accepted;
    }
    result.candidates += static_cast<long long>(cands.size());
    result.frames_with_ball += any;
    ++result.frames;
    if (writer || !draw_dir.empty() || !draw_image.empty()) {
      cv::Mat canvas = frame.bgr.clone();
      DrawFieldBoundary(canvas, detector.colour().OffFieldBoundary(frame.bgr));
      DrawCandidates(canvas, cands);
      if (legend.cols != canvas.cols) legend = CandidateLegend(canvas.cols);
      cv::vconcat(canvas, legend, canvas);
      if (writer) {
        writer->Write(canvas);
      } else if (!draw_image.empty()) {
        io::WriteImage(draw_image, canvas);
      } else {
        const std::string path = fmt::format("{}/{:05d}.jpg", draw_dir, frame.index);
        FV_REQUIRE(codecs::ImWrite(path, canvas), "cannot write '{}'", path);
      }
    }
    progress.Update(result.frames);
  }
  progress.Finish();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  FV_REQUIRE(result.frames > 0, "video '{}' has no frames", o.video);
  if (writer) {
    writer->Close();
    result.drawn =
        fmt::format("{} ({} frames, {}){}", writer->path(), writer->frames(), writer->codec(),
                    writer->note().empty() ? "" : "; " + writer->note());
  } else if (!draw_dir.empty()) {
    result.drawn = fmt::format("{} ({} JPEGs)", draw_dir, result.frames);
  } else if (!draw_image.empty()) {
    result.drawn = draw_image;
  }
  result.background = NeededBackgroundSummary(background);
  result.frames_note = util::JoinNonEmpty({camera_note, source->frames_note()}, "; ");
  out_file.CloseAndCommit(csv);
  return result;
}

}  // namespace fv::detect
