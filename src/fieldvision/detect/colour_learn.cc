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

namespace fv::detect {
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

// The box around a region that holds its ring of background: 1.5 times its size.
cv::Rect AroundRoi(const cv::Rect& r) {
  return cv::Rect(r.x - r.width / 4, r.y - r.height / 4, r.width * 3 / 2, r.height * 3 / 2);
}

// One frame's pixels as the options give them (the one-frame calls).
ColourLearnSample SampleOf(const cv::Mat& bgr, const ColourLearnOptions& o) {
  ColourLearnSample sample;
  sample.bgr = bgr;
  sample.points = o.points;
  if (o.roi) sample.boxes.push_back(*o.roi);
  sample.negative_points = o.negative_points;
  return sample;
}

}  // namespace

void ColourLearnOptions::Check(bool need_pixels) const {
  FV_REQUIRE(!need_pixels || !points.empty() || roi.has_value(),
             "give --points or --roi (the ball's pixels)");
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
  for (const std::string& item : util::Split(text, ';')) {
    const std::string t = util::Trim(item);
    if (t.empty()) continue;
    const auto uv = util::Split(t, ',');
    FV_REQUIRE(uv.size() == 2, "{}: '{}' is not u,v", what, t);
    pts.emplace_back(util::ParseDouble(util::Trim(uv[0]), what),
                     util::ParseDouble(util::Trim(uv[1]), what));
  }
  FV_REQUIRE(!pts.empty(), "{}: no points in '{}' (expected u,v;u,v...)", what, text);
  return pts;
}

cv::Rect ParseRect(const std::string& text, const std::string& what) {
  const auto v = util::Split(text, ',');
  FV_REQUIRE(v.size() == 4, "{}: '{}' is not x,y,w,h", what, text);
  cv::Rect r(static_cast<int>(util::ParseInt(util::Trim(v[0]), what)),
             static_cast<int>(util::ParseInt(util::Trim(v[1]), what)),
             static_cast<int>(util::ParseInt(util::Trim(v[2]), what)),
             static_cast<int>(util::ParseInt(util::Trim(v[3]), what)));
  FV_REQUIRE(r.width > 0 && r.height > 0, "{}: width and height must be > 0", what);
  return r;
}

cv::Mat ReadVideoFrame(const std::string& video, int frame_index) {
  return ReadVideoFrames(video, {frame_index}).front();
}

std::vector<cv::Mat> ReadVideoFrames(const std::string& video, const std::vector<int>& frames) {
  for (const int f : frames) FV_REQUIRE(f >= 0, "--frame must be >= 0 (got {})", f);
  std::vector<cv::Mat> out(frames.size());
  if (frames.empty()) return out;
  const int last = *std::max_element(frames.begin(), frames.end());
  auto source = io::VideoSource::Open(video);
  io::Frame frame;
  while (source->Read(frame)) {
    for (size_t i = 0; i < frames.size(); ++i) {
      if (frames[i] == frame.index) out[i] = frame.bgr.clone();
    }
    if (frame.index == last) return out;
  }
  Throw("video '{}' has only {} frames; frame {} does not exist", video, source->frames_read(),
        last);
}

ColourLearnMasks MarkLearnPixels(const cv::Mat& bgr, const ColourLearnOptions& o) {
  return MarkLearnPixels(SampleOf(bgr, o), o.point_radius_px);
}

ColourLearnMasks MarkLearnPixels(const ColourLearnSample& sample, int point_radius_px) {
  const cv::Mat& bgr = sample.bgr;
  const cv::Rect frame_rect(0, 0, bgr.cols, bgr.rows);
  ColourLearnMasks m;
  m.positive = cv::Mat(bgr.size(), CV_8U, cv::Scalar(0));
  m.negative = cv::Mat(bgr.size(), CV_8U, cv::Scalar(0));
  m.near = cv::Mat(bgr.size(), CV_8U, cv::Scalar(0));
  for (const auto& p : sample.points) {
    FV_REQUIRE(p.x() >= 0 && p.y() >= 0 && p.x() < bgr.cols && p.y() < bgr.rows,
               "point ({}, {}) is outside the {}x{} frame", p.x(), p.y(), bgr.cols, bgr.rows);
    const cv::Point c(cvRound(p.x()), cvRound(p.y()));
    cv::circle(m.positive, c, point_radius_px, 255, cv::FILLED);
    cv::circle(m.near, c, 40, 255, cv::FILLED);
  }
  for (const cv::Rect& r : sample.boxes) {
    FV_REQUIRE(r.area() > 0 && (r & frame_rect) == r,
               "region {},{},{},{} is not inside the {}x{} frame", r.x, r.y, r.width, r.height,
               bgr.cols, bgr.rows);
    // The ball's interior: the inscribed ellipse shrunk by 20 %.
    cv::ellipse(m.positive, cv::Point(r.x + r.width / 2, r.y + r.height / 2),
                cv::Size(std::max(1, int(0.4 * r.width)), std::max(1, int(0.4 * r.height))), 0, 0,
                360, 255, cv::FILLED);
    m.near(AroundRoi(r) & frame_rect).setTo(255);
    DropBackgroundLikePixels(bgr, r, m.positive);
  }
  for (const auto& p : sample.negative_points) {
    FV_REQUIRE(p.x() >= 0 && p.y() >= 0 && p.x() < bgr.cols && p.y() < bgr.rows,
               "negative point ({}, {}) is outside the {}x{} frame", p.x(), p.y(), bgr.cols,
               bgr.rows);
    cv::circle(m.negative, cv::Point(cvRound(p.x()), cvRound(p.y())), point_radius_px, 255,
               cv::FILLED);
  }
  return m;
}

// A box whose centre is at least this saturated holds a coloured ball (DropBackgroundLikePixels).
constexpr double kColouredCentre = 0.3;

void DropBackgroundLikePixels(const cv::Mat& bgr, const cv::Rect& roi, cv::Mat& positive) {
  const cv::Rect frame_rect(0, 0, bgr.cols, bgr.rows);
  const cv::Rect& r = roi;
  const cv::Point c(r.x + r.width / 2, r.y + r.height / 2);
  const cv::Scalar centre = cv::mean(bgr(cv::Rect(c.x - 1, c.y - 1, 3, 3) & frame_rect));
  std::array<std::vector<int>, 3> ring;
  const cv::Rect outer = AroundRoi(r) & frame_rect;
  for (int y = outer.y; y < outer.y + outer.height; ++y) {
    for (int x = outer.x; x < outer.x + outer.width; ++x) {
      if (r.contains(cv::Point(x, y))) continue;
      const cv::Vec3b& p = bgr.at<cv::Vec3b>(y, x);
      for (int k = 0; k < 3; ++k) ring[k].push_back(p[k]);
    }
  }
  if (ring[0].empty()) return;
  cv::Vec3d bg;
  for (int k = 0; k < 3; ++k) bg[k] = util::NearestRankPercentile(ring[k], 0.5);
  // Saturation (max - min) / max. The box of a coloured ball often holds a white line or a
  // highlight too, whose hue is noise: its pixels would widen the learned hue range to the
  // background's. They are left out when the centre is coloured (a white ball keeps them).
  const auto saturation = [](double b, double g, double rr) {
    const double hi = std::max({b, g, rr}), lo = std::min({b, g, rr});
    return hi > 0 ? (hi - lo) / hi : 0.0;
  };
  const double centre_sat = saturation(centre[0], centre[1], centre[2]);
  const double min_sat = centre_sat >= kColouredCentre ? 0.5 * centre_sat : 0.0;
  for (int y = r.y; y < r.y + r.height; ++y) {
    for (int x = r.x; x < r.x + r.width; ++x) {
      if (!positive.at<uint8_t>(y, x)) continue;
      const cv::Vec3b& p = bgr.at<cv::Vec3b>(y, x);
      double dc = 0, db = 0;
      for (int k = 0; k < 3; ++k) {
        dc += (p[k] - centre[k]) * (p[k] - centre[k]);
        db += (p[k] - bg[k]) * (p[k] - bg[k]);
      }
      if (db <= dc || saturation(p[0], p[1], p[2]) < min_sat) positive.at<uint8_t>(y, x) = 0;
    }
  }
}

ColourLearnPixels GatherLearnPixels(const cv::Mat& hsv, const ColourLearnMasks& m) {
  ColourLearnPixels px;
  for (int y = 0; y < hsv.rows; ++y) {
    for (int x = 0; x < hsv.cols; ++x) {
      if (m.positive.at<uint8_t>(y, x)) {
        px.positive.push_back(hsv.at<Hsv8>(y, x));
      } else if (m.negative.at<uint8_t>(y, x) ||
                 (!m.near.at<uint8_t>(y, x) && (x % 3 == 0) && (y % 3 == 0))) {
        px.negative.push_back(hsv.at<Hsv8>(y, x));  // clicked, or the frame away from the ball
      }
    }
  }
  return px;
}

std::pair<int, int> ShortestHueInterval(const std::vector<cv::Vec3b>& hsv, double trim) {
  std::vector<int> hist(256, 0);
  for (const auto& p : hsv) ++hist[p[0]];
  const int need = static_cast<int>(std::ceil((1.0 - 2 * trim) * hsv.size()));
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
  return {best_start, best_len};
}

ColourRange InitialColourRange(const std::vector<cv::Vec3b>& positive,
                               const ColourLearnOptions& o) {
  const auto [best_start, best_len] = ShortestHueInterval(positive, o.trim);
  // Nearest-rank percentiles (RankPercentile): the same pixels given twice (clicks on two
  // frames of a still ball) learn the same class.
  std::vector<double> s, v;
  for (const auto& p : positive) {
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
  r.min[1] = std::max(0.0, util::RankPercentile(s, o.trim) - o.saturation_margin);
  r.max[1] = 255;
  r.min[2] = std::max(0.0, util::RankPercentile(v, o.trim) - o.value_margin);
  r.max[2] = 255;
  return r;
}

ColourRange ShrinkAgainstNegatives(ColourRange r, const ColourLearnPixels& px, double min_recall) {
  const auto& pos = px.positive;
  const auto& neg = px.negative;
  double recall = ColourRangeShare(r, pos), neg_rate = ColourRangeShare(r, neg);
  for (int iter = 0; iter < 200 && neg_rate > 0.001; ++iter) {
    ColourRange best = r;
    double best_gain = 0;
    for (int move = 0; move < 4; ++move) {
      ColourRange t = r;
      if (move == 0) t.min[1] = std::min(t.min[1] + 5, 250.0);
      if (move == 1) t.min[2] = std::min(t.min[2] + 5, 250.0);
      if (move == 2) t.min[0] = std::fmod(t.min[0] + 1.40625, 360.0);
      if (move == 3) t.max[0] = std::fmod(t.max[0] - 1.40625 + 360.0, 360.0);
      const double rec = ColourRangeShare(t, pos);
      if (rec < min_recall) continue;
      const double gain = (neg_rate - ColourRangeShare(t, neg)) - 0.2 * (recall - rec);
      if (gain > best_gain) {
        best_gain = gain;
        best = t;
      }
    }
    if (best_gain <= 0) break;
    r = best;
    recall = ColourRangeShare(r, pos);
    neg_rate = ColourRangeShare(r, neg);
  }
  return r;
}

double ColourRangeShare(const ColourRange& r, const std::vector<cv::Vec3b>& hsv) {
  if (hsv.empty()) return 0.0;
  size_t n = 0;
  for (const auto& p : hsv) n += Inside(r, p);
  return double(n) / hsv.size();
}

ColourSpec LearnedColourSpec(const ColourRange& r, const std::string& class_name) {
  ColourSpec spec;
  spec.classes.push_back({class_name, {r}});
  if (class_name != "field") spec.classes.push_back({"field", ColourPreset("green").ranges});
  if (class_name != "line") spec.classes.push_back({"line", ColourPreset("white").ranges});
  spec.ball_class = class_name;
  spec.Check("learned colour");
  return spec;
}

cv::Mat LearnOverlay(const cv::Mat& bgr, const ColourSpec& spec, const cv::Mat& positive) {
  // The class at full brightness, everything else dimmed; the positives outlined.
  const ColourTable table(spec, 8);
  const cv::Mat cls = table.ClassifyImage(bgr) & table.BallBit();
  cv::Mat overlay = bgr * 0.25;
  bgr.copyTo(overlay, cls);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(positive, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::drawContours(overlay, contours, -1, cv::Scalar(255, 0, 255), 1, cv::LINE_AA);
  return overlay;
}

ColourLearnResult LearnColour(const cv::Mat& bgr, const ColourLearnOptions& o) {
  o.Check();
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "colour learn: the frame is not 8-bit BGR");
  return LearnColour(std::vector<ColourLearnSample>{SampleOf(bgr, o)}, o);
}

ColourLearnResult LearnColour(const std::vector<ColourLearnSample>& samples,
                              const ColourLearnOptions& o) {
  o.Check(/*need_pixels=*/false);
  FV_REQUIRE(!samples.empty(), "colour learn: no frames to learn from");
  const size_t budget = std::max<size_t>(1, kMaxLearnNegatives / samples.size());
  ColourLearnPixels px;
  cv::Mat first_positive;
  for (size_t i = 0; i < samples.size(); ++i) {
    const ColourLearnSample& sample = samples[i];
    FV_REQUIRE(!sample.bgr.empty() && sample.bgr.type() == CV_8UC3,
               "colour learn: frame {} is not 8-bit BGR", i);
    FV_REQUIRE(!sample.points.empty() || !sample.boxes.empty(),
               "colour learn: frame {} has no ball pixels (points or boxes)", i);
    cv::Mat hsv;
    cv::cvtColor(sample.bgr, hsv, cv::COLOR_BGR2HSV_FULL);
    const ColourLearnMasks masks = MarkLearnPixels(sample, o.point_radius_px);
    const ColourLearnPixels frame_px = GatherLearnPixels(hsv, masks);
    px.positive.insert(px.positive.end(), frame_px.positive.begin(), frame_px.positive.end());
    const size_t n = frame_px.negative.size();
    const size_t stride = (n + budget - 1) / budget;
    for (size_t k = 0; k < n; k += std::max<size_t>(stride, 1)) {
      px.negative.push_back(frame_px.negative[k]);
    }
    if (i == 0) first_positive = masks.positive;
  }
  FV_REQUIRE(px.positive.size() >= 5,
             "only {} positive pixels; give more points or a larger region", px.positive.size());
  // Without background the purity check cannot fail: a box over the whole frame learned a class
  // of every colour, written as good.
  FV_REQUIRE(px.negative.size() >= 50,
             "colour learn: {} background pixels outside the ball's boxes (a box over the whole "
             "frame?): a class cannot be checked against the background; box the ball tightly, or "
             "mark background with --negative",
             px.negative.size());
  ColourLearnResult result;
  result.range = ShrinkAgainstNegatives(InitialColourRange(px.positive, o), px, o.min_recall);
  result.positives = static_cast<int>(px.positive.size());
  result.negatives = static_cast<int>(px.negative.size());
  result.recall = ColourRangeShare(result.range, px.positive);
  result.negative_rate = ColourRangeShare(result.range, px.negative);
  result.bad = result.negative_rate > o.max_background_share;
  result.spec = LearnedColourSpec(result.range, o.class_name);
  result.overlay = LearnOverlay(samples.front().bgr, result.spec, first_positive);
  return result;
}

}  // namespace fv::detect
