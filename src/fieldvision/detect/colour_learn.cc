#include "fieldvision/detect/colour_learn.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/io/video_source.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/strings.h"

namespace fv {
namespace {

// HSV_FULL pixels (hue 0..255 for 0..360 degrees).
using Hsv8 = cv::Vec3b;

// The table's view of a range, on 8-bit HSV_FULL values.
bool Inside(const ColourRange& r, const Hsv8& p) {
  const double h = p[0] * 360.0 / 256.0;
  const bool hue =
      r.min[0] <= r.max[0] ? (h >= r.min[0] && h <= r.max[0]) : (h >= r.min[0] || h <= r.max[0]);
  return hue && p[1] >= r.min[1] && p[1] <= r.max[1] && p[2] >= r.min[2] && p[2] <= r.max[2];
}

double Share(const ColourRange& r, const std::vector<Hsv8>& px) {
  if (px.empty()) return 0.0;
  size_t n = 0;
  for (const auto& p : px) n += Inside(r, p);
  return double(n) / px.size();
}

}  // namespace

void ColourLearnOptions::Check() const {
  FV_REQUIRE(!points.empty() || roi.has_value(), "give --points or --roi (the ball's pixels)");
  FV_REQUIRE(point_radius_px >= 0 && point_radius_px <= 20, "point_radius_px must be 0..20");
  CheckInRange(trim, 0.0, 0.2, "trim");
  CheckInRange(hue_margin_deg, 0.0, 90.0, "hue_margin_deg");
  CheckInRange(saturation_margin, 0.0, 255.0, "saturation_margin");
  CheckInRange(value_margin, 0.0, 255.0, "value_margin");
  CheckInRange(min_recall, 0.0, 1.0, "min_recall");
  CheckInRange(max_background_share, 0.0, 1.0, "max_background_share");
  FV_REQUIRE(!class_name.empty(), "class_name is empty");
}

std::string ColourLearnResult::Summary() const {
  return fmt::format(
             "class '{}': hue {:.0f}..{:.0f} deg, saturation {:.0f}..{:.0f}, value {:.0f}..{:.0f}; "
             "{} positive pixels ({:.1f} % inside), {} negative pixels ({:.2f} % inside)",
             spec.ball_class, range.min[0], range.max[0], range.min[1], range.max[1], range.min[2],
             range.max[2], positives, 100 * recall, negatives, 100 * negative_rate) +
         (bad ? fmt::format("\nBAD CLASS: it selects {:.1f} % of the background (more than the "
                            "allowed share): point at the ball more tightly or add --negative",
                            100 * negative_rate)
              : "");
}

std::vector<Eigen::Vector2d> ParsePoints(const std::string& text, const std::string& what) {
  std::vector<Eigen::Vector2d> pts;
  for (const std::string& item : Split(text, ';')) {
    const std::string t = Trim(item);
    if (t.empty()) continue;
    const auto uv = Split(t, ',');
    FV_REQUIRE(uv.size() == 2, "{}: '{}' is not u,v", what, t);
    pts.emplace_back(ParseDouble(Trim(uv[0]), what), ParseDouble(Trim(uv[1]), what));
  }
  FV_REQUIRE(!pts.empty(), "{}: no points in '{}' (expected u,v;u,v...)", what, text);
  return pts;
}

cv::Rect ParseRect(const std::string& text, const std::string& what) {
  const auto v = Split(text, ',');
  FV_REQUIRE(v.size() == 4, "{}: '{}' is not x,y,w,h", what, text);
  cv::Rect r(
      static_cast<int>(ParseInt(Trim(v[0]), what)), static_cast<int>(ParseInt(Trim(v[1]), what)),
      static_cast<int>(ParseInt(Trim(v[2]), what)), static_cast<int>(ParseInt(Trim(v[3]), what)));
  FV_REQUIRE(r.width > 0 && r.height > 0, "{}: width and height must be > 0", what);
  return r;
}

cv::Mat ReadVideoFrame(const std::string& video, int frame_index) {
  FV_REQUIRE(frame_index >= 0, "--frame must be >= 0 (got {})", frame_index);
  auto source = VideoSource::Open(video);
  Frame frame;
  while (source->Read(frame)) {
    if (frame.index == frame_index) return frame.bgr;
  }
  Throw("video '{}' has only {} frames; frame {} does not exist", video, source->frames_read(),
        frame_index);
}

ColourLearnResult LearnColour(const cv::Mat& bgr, const ColourLearnOptions& o) {
  o.Check();
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "colour learn: the frame is not 8-bit BGR");
  const cv::Rect frame_rect(0, 0, bgr.cols, bgr.rows);
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV_FULL);
  cv::Mat pos_mask(bgr.size(), CV_8U, cv::Scalar(0));
  cv::Mat neg_mask(bgr.size(), CV_8U, cv::Scalar(0));
  cv::Mat near_mask(bgr.size(), CV_8U, cv::Scalar(0));  // kept out of the default negatives
  for (const auto& p : o.points) {
    FV_REQUIRE(p.x() >= 0 && p.y() >= 0 && p.x() < bgr.cols && p.y() < bgr.rows,
               "point ({}, {}) is outside the {}x{} frame", p.x(), p.y(), bgr.cols, bgr.rows);
    const cv::Point c(cvRound(p.x()), cvRound(p.y()));
    cv::circle(pos_mask, c, o.point_radius_px, 255, cv::FILLED);
    cv::circle(near_mask, c, 40, 255, cv::FILLED);
  }
  if (o.roi) {
    const cv::Rect r = *o.roi;
    FV_REQUIRE((r & frame_rect) == r, "region {},{},{},{} is not inside the {}x{} frame", r.x, r.y,
               r.width, r.height, bgr.cols, bgr.rows);
    // The ball's interior: the inscribed ellipse shrunk by 20 %.
    cv::ellipse(pos_mask, cv::Point(r.x + r.width / 2, r.y + r.height / 2),
                cv::Size(std::max(1, int(0.4 * r.width)), std::max(1, int(0.4 * r.height))), 0, 0,
                360, 255, cv::FILLED);
    const cv::Rect grown(r.x - r.width / 4, r.y - r.height / 4, r.width * 3 / 2, r.height * 3 / 2);
    near_mask(grown & frame_rect).setTo(255);
    // A loose box also holds background: keep the pixels closer to the box centre's colour
    // than to the median colour of the ring around the box.
    const cv::Point c(r.x + r.width / 2, r.y + r.height / 2);
    const cv::Scalar centre = cv::mean(bgr(cv::Rect(c.x - 1, c.y - 1, 3, 3) & frame_rect));
    std::array<std::vector<int>, 3> ring;
    const cv::Rect outer = grown & frame_rect;
    for (int y = outer.y; y < outer.y + outer.height; ++y) {
      for (int x = outer.x; x < outer.x + outer.width; ++x) {
        if (r.contains(cv::Point(x, y))) continue;
        const cv::Vec3b& p = bgr.at<cv::Vec3b>(y, x);
        for (int k = 0; k < 3; ++k) ring[k].push_back(p[k]);
      }
    }
    if (!ring[0].empty()) {
      cv::Vec3d bg;
      for (int k = 0; k < 3; ++k) bg[k] = NearestRankPercentile(ring[k], 0.5);
      for (int y = r.y; y < r.y + r.height; ++y) {
        for (int x = r.x; x < r.x + r.width; ++x) {
          if (!pos_mask.at<uint8_t>(y, x)) continue;
          const cv::Vec3b& p = bgr.at<cv::Vec3b>(y, x);
          double dc = 0, db = 0;
          for (int k = 0; k < 3; ++k) {
            dc += (p[k] - centre[k]) * (p[k] - centre[k]);
            db += (p[k] - bg[k]) * (p[k] - bg[k]);
          }
          if (db <= dc) pos_mask.at<uint8_t>(y, x) = 0;
        }
      }
    }
  }
  for (const auto& p : o.negative_points) {
    FV_REQUIRE(p.x() >= 0 && p.y() >= 0 && p.x() < bgr.cols && p.y() < bgr.rows,
               "negative point ({}, {}) is outside the {}x{} frame", p.x(), p.y(), bgr.cols,
               bgr.rows);
    cv::circle(neg_mask, cv::Point(cvRound(p.x()), cvRound(p.y())), o.point_radius_px, 255,
               cv::FILLED);
  }
  std::vector<Hsv8> pos, neg;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      if (pos_mask.at<uint8_t>(y, x)) {
        pos.push_back(hsv.at<Hsv8>(y, x));
      } else if (neg_mask.at<uint8_t>(y, x) ||
                 (!near_mask.at<uint8_t>(y, x) && (x % 3 == 0) && (y % 3 == 0))) {
        neg.push_back(hsv.at<Hsv8>(y, x));  // clicked, or the frame away from the ball
      }
    }
  }
  FV_REQUIRE(pos.size() >= 5, "only {} positive pixels; give more points or a larger region",
             pos.size());
  // Hue: the shortest circular interval holding all but the trimmed share.
  std::vector<int> hist(256, 0);
  for (const auto& p : pos) ++hist[p[0]];
  const int need = static_cast<int>(std::ceil((1.0 - 2 * o.trim) * pos.size()));
  int best_start = 0, best_len = 256;
  for (int start = 0; start < 256; ++start) {
    int sum = 0;
    for (int len = 1; len <= 256; ++len) {
      sum += hist[(start + len - 1) % 256];
      if (sum >= need) {
        if (len < best_len) {
          best_len = len;
          best_start = start;
        }
        break;
      }
    }
  }
  std::vector<int> s, v;
  for (const auto& p : pos) {
    s.push_back(p[1]);
    v.push_back(p[2]);
  }
  ColourRange r;
  r.space = ColourSpace::kHsv;
  const double h_lo = best_start * 360.0 / 256.0 - o.hue_margin_deg;
  const double h_hi = (best_start + best_len - 1) * 360.0 / 256.0 + o.hue_margin_deg;
  if (h_hi - h_lo >= 360.0) {
    r.min[0] = 0;
    r.max[0] = 360;
  } else {
    r.min[0] = std::fmod(h_lo + 360.0, 360.0);
    r.max[0] = std::fmod(h_hi + 360.0, 360.0);
  }
  r.min[1] = std::max(0.0, NearestRankPercentile(s, o.trim) - o.saturation_margin);
  r.max[1] = 255;
  r.min[2] = std::max(0.0, NearestRankPercentile(v, o.trim) - o.value_margin);
  r.max[2] = 255;
  // Shrink against the negatives: move one bound a step at a time.
  double recall = Share(r, pos), neg_rate = Share(r, neg);
  for (int iter = 0; iter < 200 && neg_rate > 0.001; ++iter) {
    ColourRange best = r;
    double best_gain = 0;
    for (int move = 0; move < 4; ++move) {
      ColourRange t = r;
      if (move == 0) t.min[1] = std::min(t.min[1] + 5, 250.0);
      if (move == 1) t.min[2] = std::min(t.min[2] + 5, 250.0);
      if (move == 2) t.min[0] = std::fmod(t.min[0] + 1.40625, 360.0);
      if (move == 3) t.max[0] = std::fmod(t.max[0] - 1.40625 + 360.0, 360.0);
      const double rec = Share(t, pos);
      if (rec < o.min_recall) continue;
      const double gain = (neg_rate - Share(t, neg)) - 0.2 * (recall - rec);
      if (gain > best_gain) {
        best_gain = gain;
        best = t;
      }
    }
    if (best_gain <= 0) break;
    r = best;
    recall = Share(r, pos);
    neg_rate = Share(r, neg);
  }
  ColourLearnResult result;
  result.range = r;
  result.positives = static_cast<int>(pos.size());
  result.negatives = static_cast<int>(neg.size());
  result.recall = recall;
  result.negative_rate = neg_rate;
  result.bad = neg_rate > o.max_background_share;
  result.spec.classes.push_back({o.class_name, {r}});
  if (o.class_name != "field") {
    result.spec.classes.push_back({"field", ColourPreset("green").ranges});
  }
  if (o.class_name != "line") result.spec.classes.push_back({"line", ColourPreset("white").ranges});
  result.spec.ball_class = o.class_name;
  result.spec.Check("learned colour");
  // Overlay: the class at full brightness, everything else dimmed; the positives outlined.
  const ColourTable table(result.spec, 8);
  const cv::Mat cls = table.ClassifyImage(bgr) & table.BallBit();
  result.overlay = bgr * 0.25;
  bgr.copyTo(result.overlay, cls);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(pos_mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(result.overlay, contours, -1, cv::Scalar(255, 0, 255), 1, cv::LINE_AA);
  return result;
}

}  // namespace fv
