#include "fieldvision/track/overlay.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/calib/check.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/io/video_writer.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/progress.h"

namespace fv::track {

void OverlayOptions::Check() const {
  CheckNonNegative(trail_frames, "overlay trail_frames");
  FV_REQUIRE(thickness_px >= 1 && thickness_px <= 20, "overlay thickness_px must be 1..20 (got {})",
             thickness_px);
}

cv::Scalar TrackColour(int id, int team) {
  static const cv::Scalar kTeams[] = {
      {40, 40, 230}, {230, 120, 30}, {40, 220, 240}, {240, 240, 240}};
  if (team >= 0 && team < 4) return kTeams[team];
  // Without a team: colours far from the team colours (no red, blue, yellow or white).
  static const cv::Scalar kPalette[] = {
      {75, 180, 60}, {180, 30, 145}, {240, 240, 70},  {230, 50, 240}, {48, 130, 245},
      {0, 128, 128}, {40, 90, 140},  {150, 150, 150}, {60, 245, 210}, {128, 0, 128}};
  return kPalette[std::abs(id) % 10];
}

TrackOverlay::TrackOverlay(const std::vector<TrackRow>& rows, std::map<int, int> team_of,
                           std::map<int, std::string> name_of, const camera::Camera* camera,
                           const field::FieldModel* field, const OverlayOptions& options)
    : team_of_(std::move(team_of)), name_of_(std::move(name_of)), o_(options) {
  o_.Check();
  for (const auto& r : rows) by_frame_[r.frame].push_back(r);
  if (camera != nullptr && camera->has_pose && field != nullptr && o_.field_lines) {
    camera_ = std::make_unique<camera::Camera>(*camera);
    field_ = std::make_unique<field::FieldModel>(*field);
  }
  if (o_.legend) legend_ = LegendLines();
}

void TrackOverlay::SetCameraMotion(const ViewCanvas& canvas) {
  canvas_ = canvas;
  canvas_lines_.release();
  if (!camera_ || !canvas.camera().has_pose) return;
  const camera::Camera& c = canvas.camera();
  cv::Mat drawn(c.height, c.width, CV_8UC3, cv::Scalar(0, 0, 0));
  calib::DrawFieldOverlay(drawn, c, *field_, cv::Scalar(255, 255, 255), 1, 0.1);
  cv::cvtColor(drawn, canvas_lines_, cv::COLOR_BGR2GRAY);
}

std::optional<cv::Point2d> TrackOverlay::TrailPoint(const cv::Point2d& foot, int from_frame,
                                                    int to_frame) const {
  if (!canvas_ || from_frame == to_frame) return foot;
  const int n = canvas_->frames();
  if (from_frame < 1 || to_frame < 1 || from_frame > n || to_frame > n) return foot;
  const auto on_canvas = canvas_->ToCanvas(from_frame - 1, foot);
  if (!on_canvas) return std::nullopt;
  return canvas_->ToFrame(to_frame - 1, *on_canvas);
}

void TrackOverlay::Draw(cv::Mat& bgr, int frame) const {
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "overlay: expected a BGR frame");
  // The field lines, drawn half-transparent so the players stay visible; a moving camera's are
  // what this frame sees of them on the canvas.
  cv::Mat lines;
  if (camera_ && !canvas_) {
    lines = bgr.clone();
    calib::DrawFieldOverlay(lines, *camera_, *field_, o_.field_colour, 1, 0.1);
  } else if (!canvas_lines_.empty() && frame >= 1 && frame <= canvas_->frames() &&
             bgr.cols == canvas_->lens().width && bgr.rows == canvas_->lens().height) {
    const cv::Mat seen = canvas_->SeenByFrame(frame - 1, canvas_lines_);
    lines = bgr.clone();
    lines.setTo(o_.field_colour, seen > 64);
  }
  if (!lines.empty()) cv::addWeighted(lines, 0.6, bgr, 0.4, 0.0, bgr);
  // Under the tracks: players in its corner stay in full colour.
  if (o_.legend) DrawLegend(bgr);
  const double scale = std::max(0.4, bgr.rows / 1000.0);
  // Trails: foot points of the last trail_frames frames, per id.
  if (o_.trail_frames > 0) {
    std::map<int, std::vector<cv::Point>> trail;
    for (auto it = by_frame_.lower_bound(frame - o_.trail_frames);
         it != by_frame_.end() && it->first <= frame; ++it) {
      // A moving camera's earlier feet are moved into this frame's view.
      for (const auto& r : it->second) {
        const auto foot =
            TrailPoint({r.box.x + 0.5 * r.box.width, r.box.y + r.box.height}, it->first, frame);
        if (foot) trail[r.id].emplace_back(cvRound(foot->x), cvRound(foot->y));
      }
    }
    for (const auto& [id, pts] : trail) {
      const auto t = team_of_.find(id);
      const cv::Scalar c = TrackColour(id, t == team_of_.end() ? -1 : t->second);
      for (size_t i = 1; i < pts.size(); ++i) {
        cv::line(bgr, pts[i - 1], pts[i], c, o_.thickness_px, cv::LINE_AA);
      }
    }
  }
  const auto rows = by_frame_.find(frame);
  std::optional<double> time_s;
  if (rows != by_frame_.end()) {
    for (const auto& r : rows->second) {
      const auto t = team_of_.find(r.id);
      const cv::Scalar c = TrackColour(r.id, t == team_of_.end() ? -1 : t->second);
      // Boxes carried without a detection (conf 0: interpolated or predicted) are dashed.
      const cv::Rect box(r.box);
      if (r.conf > 0) {
        cv::rectangle(bgr, box, c, o_.thickness_px, cv::LINE_AA);
      } else {
        for (int x = box.x; x < box.x + box.width; x += 8) {
          cv::line(bgr, {x, box.y}, {std::min(x + 4, box.x + box.width), box.y}, c, 1);
          cv::line(bgr, {x, box.y + box.height},
                   {std::min(x + 4, box.x + box.width), box.y + box.height}, c, 1);
        }
        for (int y = box.y; y < box.y + box.height; y += 8) {
          cv::line(bgr, {box.x, y}, {box.x, std::min(y + 4, box.y + box.height)}, c, 1);
          cv::line(bgr, {box.x + box.width, y},
                   {box.x + box.width, std::min(y + 4, box.y + box.height)}, c, 1);
        }
      }
      const auto n = name_of_.find(r.id);
      const std::string label =
          n != name_of_.end() && !n->second.empty() ? n->second : std::to_string(r.id);
      int base = 0;
      const cv::Size ts = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.5 * scale, 1, &base);
      const cv::Point org(box.x, std::max(ts.height + 2, box.y - 3));
      cv::rectangle(bgr, org + cv::Point(-1, base), org + cv::Point(ts.width + 1, -ts.height - 2),
                    c, cv::FILLED);
      const double lum = 0.114 * c[0] + 0.587 * c[1] + 0.299 * c[2];
      cv::putText(bgr, label, org, cv::FONT_HERSHEY_SIMPLEX, 0.5 * scale,
                  lum > 140 ? cv::Scalar(0, 0, 0) : cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
      if (r.time_s) time_s = r.time_s;
    }
  }
  if (o_.time_label) {
    const std::string text = time_s ? fmt::format("frame {}  t = {:.2f} s", frame, *time_s)
                                    : fmt::format("frame {}", frame);
    const cv::Point org(8, static_cast<int>(24 * scale));
    cv::putText(bgr, text, org, cv::FONT_HERSHEY_SIMPLEX, 0.6 * scale, {0, 0, 0}, 3, cv::LINE_AA);
    cv::putText(bgr, text, org, cv::FONT_HERSHEY_SIMPLEX, 0.6 * scale, {255, 255, 255}, 1,
                cv::LINE_AA);
  }
}

std::vector<TrackOverlay::LegendLine> TrackOverlay::LegendLines() const {
  // A swatch per team of the tracks drawn (TrackColour's four), and a line for the colours by id
  // when some track has none of those teams.
  std::set<int> teams;
  bool by_id = false;
  for (const auto& [frame, rows] : by_frame_) {
    for (const TrackRow& r : rows) {
      const auto t = team_of_.find(r.id);
      if (t != team_of_.end() && t->second >= 0 && t->second < 4) {
        teams.insert(t->second);
      } else {
        by_id = true;
      }
    }
  }
  std::vector<LegendLine> lines;
  lines.reserve(teams.size() + 4);
  for (int team : teams) lines.push_back({{TrackColour(0, team)}, fmt::format("team {}", team)});
  if (by_id) {
    lines.push_back({{TrackColour(0, -1), TrackColour(1, -1), TrackColour(2, -1)},
                     teams.empty() ? "a colour per player id" : "no team: a colour per id"});
  }
  lines.push_back({{}, "solid box: detected; dashed: carried without a detection"});
  if (o_.trail_frames > 0) {
    lines.push_back({{}, fmt::format("trail: feet over the last {} frames", o_.trail_frames)});
  }
  if (camera_) lines.push_back({{o_.field_colour}, "the field's lines"});
  return lines;
}

void TrackOverlay::DrawLegend(cv::Mat& bgr) const {
  const double scale = std::max(0.8, bgr.rows / 1000.0);  // legible on 480-row video
  const double font = 0.45 * scale;
  const int line_h = cvRound(18 * scale), swatch = cvRound(10 * scale), pad = cvRound(6 * scale);
  int width = 0;
  for (const auto& [swatches, text] : legend_) {
    int base = 0;
    const int w = static_cast<int>(swatches.size()) * (swatch + 3) +
                  cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, font, 1, &base).width;
    width = std::max(width, w);
  }
  const cv::Rect box(0, bgr.rows - static_cast<int>(legend_.size()) * line_h - 2 * pad,
                     width + 2 * pad + 4, static_cast<int>(legend_.size()) * line_h + 2 * pad);
  // A legend that would hide much of a small video is left out.
  if (box.y < bgr.rows * 2 / 3 || box.width > bgr.cols * 2 / 3) return;
  cv::Mat shaded = bgr(box);
  shaded *= 0.35;  // darkened, the video still seen through it
  for (size_t i = 0; i < legend_.size(); ++i) {
    int x = box.x + pad;
    const int y = box.y + pad + static_cast<int>(i + 1) * line_h - cvRound(5 * scale);
    for (const cv::Scalar& c : legend_[i].swatches) {
      cv::rectangle(bgr, cv::Rect(x, y - swatch, swatch, swatch), c, cv::FILLED);
      x += swatch + 3;
    }
    cv::putText(bgr, legend_[i].text, cv::Point(x + 2, y), cv::FONT_HERSHEY_SIMPLEX, font,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
}

std::string DrawVideoResult::Summary() const {
  return fmt::format("wrote {} ({} frames, {}){}", path, frames, codec,
                     note.empty() ? "" : "; " + note);
}

DrawVideoResult DrawTracksVideo(const std::string& video, const std::string& out,
                                const TrackOverlay& overlay, double fps, int max_frames) {
  auto source = io::VideoSource::Open(video);
  const double rate = fps > 0 ? fps : source->fps();
  io::PlayableVideoWriter writer(out, rate, {source->width(), source->height()});
  long long total = source->frame_count();
  if (max_frames > 0) total = total > 0 ? std::min<long long>(total, max_frames) : max_frames;
  util::Progress progress("drawing", total, "frames");
  io::Frame f;
  while ((max_frames <= 0 || source->frames_read() < max_frames) && source->Read(f)) {
    cv::Mat img = f.bgr.clone();
    overlay.Draw(img, f.index + 1);
    writer.Write(img);
    progress.Update(writer.frames());
  }
  progress.Finish();
  writer.Close();
  DrawVideoResult r;
  r.frames = writer.frames();
  r.frame_size = {source->width(), source->height()};
  r.path = writer.path();
  r.codec = writer.codec();
  r.note = writer.note();
  if (fps <= 0 && !source->rate_known()) {
    r.note +=
        fmt::format("{}played at {:g} frames/s: the images carry no frame rate (--fps sets it)",
                    r.note.empty() ? "" : "; ", rate);
  }
  return r;
}

}  // namespace fv::track
