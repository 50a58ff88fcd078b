#include "fieldvision/detect/eval_drawing.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <system_error>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/detect_video.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::detect {
namespace fs = std::filesystem;

namespace {

const cv::Scalar kCyan(255, 255, 0);
constexpr int kZoomPx = 240;  // close-up side
// The longest side an enlargement makes (JPEG holds at most 65500 px; memory).
constexpr int kMaxDrawingPx = 8000;

// Whether `inner` is `outer` or lies in it (paths compared made absolute, links followed).
bool Within(const fs::path& inner, const fs::path& outer) {
  if (inner.empty() || outer.empty()) return false;
  const fs::path a = fs::weakly_canonical(fs::absolute(inner));
  const fs::path b = fs::weakly_canonical(fs::absolute(outer));
  auto [end_b, end_a] = std::mismatch(b.begin(), b.end(), a.begin(), a.end());
  return end_b == b.end();
}

}  // namespace

int EvalDrawingScale(int width, int height) {
  const int shorter = std::max(1, std::min(width, height));
  const int longer = std::max(1, std::max(width, height));
  return std::clamp((480 + shorter - 1) / shorter, 1, std::clamp(kMaxDrawingPx / longer, 1, 8));
}

namespace {

// The part `area` of `bgr` (black where it leaves the image) enlarged k times, pixels kept
// square, with the boxes, their hit areas and the candidates drawn at their places.
cv::Mat DrawnView(const cv::Mat& bgr, const cv::Rect& area, int k,
                  const std::vector<cv::Rect2d>& boxes, double grow,
                  const std::vector<BallCandidate>& candidates) {
  cv::Mat part(area.size(), CV_8UC3, cv::Scalar::all(0));
  const cv::Rect inside = area & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (!inside.empty()) bgr(inside).copyTo(part(inside - area.tl()));
  cv::Mat view;
  cv::resize(part, view, cv::Size(), k, k, cv::INTER_NEAREST);
  // Pixel i becomes pixels k i .. k i + k - 1: its centre moves to k i + (k - 1) / 2.
  const auto sx = [&](double x) { return k * (x - area.x) + 0.5 * (k - 1); };
  const auto sy = [&](double y) { return k * (y - area.y) + 0.5 * (k - 1); };
  constexpr int kShift = 4;
  const auto corner = [&](double x, double y) {
    return cv::Point(cvRound(sx(x) * (1 << kShift)), cvRound(sy(y) * (1 << kShift)));
  };
  for (const cv::Rect2d& b : boxes) {
    const cv::Rect2d g(b.x - grow * b.width, b.y - grow * b.height, b.width * (1 + 2 * grow),
                       b.height * (1 + 2 * grow));
    cv::rectangle(view, corner(g.x, g.y), corner(g.x + g.width, g.y + g.height), kCyan, 1,
                  cv::LINE_AA, kShift);
    cv::rectangle(view, corner(b.x, b.y), corner(b.x + b.width, b.y + b.height), kCyan, 2,
                  cv::LINE_AA, kShift);
  }
  std::vector<BallCandidate> drawn = candidates;
  for (BallCandidate& c : drawn) {
    c.centre_px = Eigen::Vector2d(sx(c.centre_px.x()), sy(c.centre_px.y()));
    c.radius_px *= k;
  }
  DrawCandidates(view, drawn);
  return view;
}

// `a` above `b`, the narrower one padded on the right with black.
cv::Mat Stack(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty()) return b;
  const int width = std::max(a.cols, b.cols);
  cv::Mat out(a.rows + b.rows, width, CV_8UC3, cv::Scalar::all(0));
  a.copyTo(out(cv::Rect(0, 0, a.cols, a.rows)));
  b.copyTo(out(cv::Rect(0, a.rows, b.cols, b.rows)));
  return out;
}

}  // namespace

cv::Mat DrawEvalImage(const cv::Mat& bgr, const std::vector<cv::Rect2d>& boxes, double grow,
                      const std::vector<BallCandidate>& candidates,
                      const std::vector<std::string>& title, const std::vector<EvalZoom>& zooms) {
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "DrawEvalImage: needs a BGR image");
  const int k = EvalDrawingScale(bgr.cols, bgr.rows);
  const cv::Mat frame =
      DrawnView(bgr, cv::Rect(0, 0, bgr.cols, bgr.rows), k, boxes, grow, candidates);
  // Close-ups, in a column beside the frame, of what it shows too small.
  cv::Mat column;
  for (const EvalZoom& z : zooms) {
    const int side =
        std::max(24, static_cast<int>(std::ceil(3 * std::max(z.around.width, z.around.height))));
    const int kz = std::max(1, kZoomPx / side);
    if (kz <= k) continue;
    const cv::Point2d c(z.around.x + 0.5 * z.around.width, z.around.y + 0.5 * z.around.height);
    const cv::Rect area(cvRound(c.x - 0.5 * side), cvRound(c.y - 0.5 * side), side, side);
    column = Stack(column, TextBand({fmt::format("{} x{}", z.caption, kz)}, kZoomPx));
    column = Stack(column, DrawnView(bgr, area, kz, boxes, grow, candidates));
  }
  cv::Mat canvas = frame;
  if (!column.empty()) {
    canvas = cv::Mat(std::max(frame.rows, column.rows), frame.cols + 4 + column.cols, CV_8UC3,
                     cv::Scalar::all(0));
    frame.copyTo(canvas(cv::Rect(0, 0, frame.cols, frame.rows)));
    column.copyTo(canvas(cv::Rect(frame.cols + 4, 0, column.cols, column.rows)));
  }
  const std::string legend = fmt::format(
      "cyan box: the labelled ball; thin cyan: where a hit's centre lies (grown {:.0f} "
      "%); green: accepted candidate (score); red: rejected candidate; image x{}",
      100 * grow, k);
  cv::Mat out;
  cv::vconcat(
      std::vector<cv::Mat>{TextBand(title, canvas.cols), canvas, TextBand({legend}, canvas.cols)},
      out);
  return out;
}

MissDrawings::MissDrawings(const std::string& dir, const std::string& video,
                           const std::vector<std::string>& image_files)
    : dir_(dir) {
  std::error_code ec;
  FV_REQUIRE(!fs::exists(dir, ec) || fs::is_directory(dir, ec),
             "--draw-misses: '{}' exists and is not a folder", dir);
  // The folders a later run over the same images would list: --video's, each image's.
  std::set<std::string> folders;
  if (fs::is_directory(video, ec)) folders.insert(video);
  for (const std::string& image : image_files) {
    const fs::path parent = fs::path(image).parent_path();
    folders.insert(parent.empty() ? "." : parent.string());
  }
  for (const std::string& folder : folders) {
    FV_REQUIRE(!Within(dir, folder),
               "--draw-misses: folder '{}' lies in the images' folder '{}' (a later run would "
               "score the drawings); name one outside it",
               dir, folder);
  }
  folder_.emplace(dir, "--draw-misses");
}

bool MissDrawings::Add(int index, const LabelledImage& item, const DetectEvalImage& scored,
                       const std::vector<BallCandidate>& candidates, const cv::Mat& bgr,
                       double grow) {
  const bool miss = scored.boxes > 0 && !scored.hit;
  const bool false_detection = scored.detected && !scored.hit;
  if (!miss && !false_detection) return false;
  std::vector<std::string> title = {item.image};
  if (false_detection) {
    title.push_back(fmt::format("false detection at ({:.1f}, {:.1f}) r {:.1f} px, score {:.2f}",
                                scored.u, scored.v, scored.radius_px, scored.score));
  }
  if (miss) title.push_back("miss: " + (scored.reason.empty() ? "no candidate" : scored.reason));
  std::vector<EvalZoom> zooms;
  if (!item.boxes.empty()) zooms.push_back({item.boxes.front(), "labelled ball"});
  if (false_detection) {
    const double r = std::max(scored.radius_px, 2.0);
    zooms.push_back({cv::Rect2d(scored.u - r, scored.v - r, 2 * r, 2 * r), "false detection"});
  }
  const cv::Mat drawing = DrawEvalImage(bgr, item.boxes, grow, candidates, title, zooms);
  const std::string name = item.frame >= 0 ? fmt::format("frame{:05d}", item.frame)
                                           : fs::path(item.image).stem().string();
  const std::string path = fmt::format("{}/{:05d}_{}_{}.jpg", dir_, index, miss ? "miss" : "false",
                                       util::FileNamePart(name));
  io::WriteImage(path, drawing);
  ++written_;
  return true;
}

}  // namespace fv::detect
