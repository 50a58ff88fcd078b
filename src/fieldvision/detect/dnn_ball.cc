#include "fieldvision/detect/dnn_ball.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/search_area.h"
#include "fieldvision/util/error.h"

namespace fv::detect {
namespace {

constexpr double kPadGrey = 114.0;  // fill beyond the image in a crop (the usual letterbox grey)
constexpr double kLowestCropScore = 0.01;  // network boxes read in a crop when scores are averaged

int RoundUp32(double v) { return std::max(32, static_cast<int>(std::ceil(v / 32.0)) * 32); }

// Whether a network box (centre, half size) confirms a candidate: holds its centre, similar size.
bool Confirms(const Eigen::Vector2d& centre, double radius, const cv::Rect2d& box,
              double size_ratio) {
  const double half = 0.25 * (box.width + box.height);
  return centre.x() >= box.x && centre.x() <= box.x + box.width && centre.y() >= box.y &&
         centre.y() <= box.y + box.height && half <= size_ratio * radius &&
         half * size_ratio >= radius;
}

// The network score that confirms colour candidate `c` (DnnBallOptions::confirm_score).
double ConfirmScore(const BallCandidate& c, const DnnBallOptions& o) {
  return c.off_field ? std::max(o.confirm_score, o.accept_score) : o.confirm_score;
}

// Whether a colour-accepted candidate the network does not confirm is kept.
bool KeptUnconfirmed(const BallCandidate& c, const DnnBallOptions& o) {
  return !o.demote_unconfirmed || c.score >= o.keep_score ||
         (o.keep_field_share > 0 && c.field_share >= o.keep_field_share);
}

// The candidate's crop side in pixels.
int CropSide(const BallCandidate& c, const DnnBallOptions& o) {
  return std::max(o.min_crop_px, static_cast<int>(std::lround(2.0 * o.crop_radii * c.radius_px)));
}

}  // namespace

void DnnBallOptions::Check() const {
  FV_REQUIRE(detector == "colour" || detector == "dnn" || detector == "both",
             "--detector must be colour, dnn or both (got '{}')", detector);
  FV_REQUIRE(
      input_width == 0 || (input_width >= 64 && input_width <= 4096 && input_width % 32 == 0),
      "dnn input_width must be 0 (from the frame) or a multiple of 32 in 64..4096 (got {})",
      input_width);
  FV_REQUIRE(min_input_width >= 64 && min_input_width <= 4096 && min_input_width % 32 == 0,
             "dnn min_input_width must be a multiple of 32 in 64..4096 (got {})", min_input_width);
  CheckInRange(score_threshold, 0.0, 1.0, "dnn score_threshold");
  CheckInRange(accept_score, 0.0, 1.0, "dnn accept_score");
  CheckInRange(complete_score, 0.0, 1.0, "dnn complete_score");
  CheckInRange(confirm_score, 0.0, 1.0, "dnn confirm_score");
  CheckInRange(keep_score, 0.0, 1.0, "dnn keep_score");
  CheckInRange(keep_field_share, 0.0, 1.0, "dnn keep_field_share");
  CheckPositive(spot_min_contrast, "dnn spot_min_contrast");
  CheckInRange(nms_iou, 0.0, 1.0, "dnn nms_iou");
  CheckInRange(crop_radii, 1.0, 20.0, "dnn crop_radii");
  FV_REQUIRE(min_crop_px >= 8, "dnn min_crop_px must be >= 8 (got {})", min_crop_px);
  FV_REQUIRE(crop_px >= 64 && crop_px <= 1024 && crop_px % 32 == 0,
             "dnn crop_px must be a multiple of 32 in 64..1024 (got {})", crop_px);
  FV_REQUIRE(max_crops >= 0 && max_crops <= 100, "dnn max_crops must be in 0..100 (got {})",
             max_crops);
  CheckInRange(box_size_ratio, 1.0, 10.0, "dnn box_size_ratio");
  CheckInRange(hold_min_radius_px, 0.0, 1000.0, "dnn hold_min_radius_px");
  CheckInRange(rescan_step_px, 0, 16, "dnn rescan_step_px");
}

BallCandidate CandidateFromBox(const dnn::DnnBox& box, double accept_score) {
  BallCandidate c;
  c.centre_px = {box.box.x + 0.5 * box.box.width, box.box.y + 0.5 * box.box.height};
  c.radius_px = 0.25 * (box.box.width + box.box.height);
  c.sigma_px = std::max(0.1 * c.radius_px, 0.3);
  c.score = box.score;
  c.network_score = box.score;
  c.accepted = box.score >= accept_score;
  c.reason = c.accepted ? "" : "network score below the accept score";
  return c;
}

void MarkOffField(const FieldBoundary& boundary, std::vector<BallCandidate>* candidates) {
  if (!boundary.valid()) return;
  for (BallCandidate& c : *candidates) {
    c.off_field = !c.accepted && boundary.DiscAbove(c.centre_px.x(), c.centre_px.y(), c.radius_px);
  }
}

std::vector<double> HoldingScores(const std::vector<BallCandidate>& colour,
                                  const std::vector<BallCandidate>& dnn, const DnnBallOptions& o,
                                  double input_scale) {
  FV_REQUIRE(std::isfinite(input_scale) && input_scale > 0,
             "HoldingScores: input scale must be positive (got {})", input_scale);
  std::vector<double> out(colour.size(), 0.0);
  for (size_t i = 0; i < colour.size(); ++i) {
    if (colour[i].radius_px * input_scale < o.hold_min_radius_px) continue;
    for (const BallCandidate& d : dnn) {
      const cv::Rect2d box(d.centre_px.x() - d.radius_px, d.centre_px.y() - d.radius_px,
                           2 * d.radius_px, 2 * d.radius_px);
      if (Confirms(colour[i].centre_px, colour[i].radius_px, box, o.box_size_ratio)) {
        out[i] = std::max(out[i], d.score);
      }
    }
  }
  return out;
}

std::vector<BallCandidate> CombineBallCandidates(const std::vector<BallCandidate>& colour,
                                                 const std::vector<double>& confirm,
                                                 const std::vector<BallCandidate>& dnn,
                                                 const DnnBallOptions& o, bool rescue) {
  FV_REQUIRE(confirm.size() == colour.size(), "CombineBallCandidates: {} scores for {} candidates",
             confirm.size(), colour.size());
  // Tiers: 0 confirmed, 1 colour-accepted unconfirmed, 2 completing network ball, 3 the rest.
  struct Ranked {
    BallCandidate c;
    int tier;
    double key;
  };
  std::vector<Ranked> ranked;
  for (size_t i = 0; i < colour.size(); ++i) {
    BallCandidate c = colour[i];
    c.network_score = confirm[i];
    if ((c.accepted || rescue) && confirm[i] >= ConfirmScore(c, o)) {
      c.rescued = !c.accepted && confirm[i] < o.accept_score;
      c.accepted = true;
      c.reason.clear();
      ranked.push_back({c, 0, confirm[i]});
    } else if (c.accepted && KeptUnconfirmed(c, o)) {
      ranked.push_back({c, 1, c.score});
    } else {
      if (c.accepted) {
        c.accepted = false;
        c.reason = fmt::format("not confirmed by the network (colour score {:.2f} < {:.2f}",
                               c.score, o.keep_score);
        if (c.field_share >= 0) {
          c.reason += fmt::format(", {:.0f} % of its ring field", 100 * c.field_share);
        }
        c.reason += ")";
      }
      ranked.push_back({c, 3, c.score});
    }
  }
  for (const BallCandidate& d : dnn) {
    // A network ball that holds a colour candidate's centre adds nothing new (the crop check
    // judged that candidate).
    const bool covered = std::any_of(colour.begin(), colour.end(), [&](const BallCandidate& c) {
      return (c.centre_px - d.centre_px).norm() <= std::max(d.radius_px, c.radius_px);
    });
    if (covered) continue;
    BallCandidate c = d;
    c.accepted = d.score >= o.complete_score;
    c.reason = c.accepted ? "" : "network score below the complete score";
    ranked.push_back({c, c.accepted ? 2 : 3, c.score});
  }
  std::stable_sort(ranked.begin(), ranked.end(), [](const Ranked& a, const Ranked& b) {
    return a.tier != b.tier ? a.tier < b.tier : a.key > b.key;
  });
  std::vector<BallCandidate> out;
  out.reserve(ranked.size());
  for (auto& r : ranked) out.push_back(std::move(r.c));
  return out;
}

DnnBallDetector::DnnBallDetector(const DnnBallOptions& options) : options_(options) {
  options_.Check();
  net_ = std::make_unique<dnn::NanoDet>(options_.model_path);
}

std::vector<BallCandidate> DnnBallDetector::Detect(const cv::Mat& bgr, const cv::Rect& roi) const {
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "dnn ball detector: expected a BGR frame");
  const cv::Rect r = SearchArea(bgr.size(), roi);
  if (r.width < 8 || r.height < 8) return {};
  const cv::Mat view = bgr(r);
  const cv::Size net_size = InputSize(bgr.size(), r);
  std::vector<dnn::DnnBox> boxes;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const double threshold = options_.detector == "both"
                                 ? std::min(options_.score_threshold, options_.confirm_score)
                                 : options_.score_threshold;
    boxes = net_->Detect(view, net_size, threshold, {dnn::kCocoSportsBall});
  }
  std::vector<BallCandidate> out;
  for (const dnn::DnnBox& b : dnn::NmsBoxes(boxes, options_.nms_iou)) {
    BallCandidate c = CandidateFromBox(b, options_.accept_score);
    c.centre_px += Eigen::Vector2d(r.x, r.y);
    out.push_back(std::move(c));
  }
  return out;
}

cv::Size DnnBallDetector::InputSize(const cv::Size& frame_size, const cv::Rect& roi) const {
  const cv::Rect r = SearchArea(frame_size, roi);
  FV_REQUIRE(!r.empty(), "dnn ball detector: empty search region");
  const int net_w = options_.input_width > 0
                        ? options_.input_width
                        : std::max(options_.min_input_width, RoundUp32(r.width));
  return {net_w, RoundUp32(net_w * static_cast<double>(r.height) / r.width)};
}

double DnnBallDetector::InputScale(const cv::Size& frame_size, const cv::Rect& roi) const {
  const int net_w = InputSize(frame_size, roi).width;  // throws for an empty search region
  return net_w / static_cast<double>(SearchArea(frame_size, roi).width);
}

double DnnBallDetector::SquareScore(const cv::Mat& square, const Eigen::Vector2d& centre_px,
                                    double radius_px) const {
  const DnnBallOptions& o = options_;
  std::vector<dnn::DnnBox> boxes;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // Mirrored crops are averaged: a score under the confirm score still counts there.
    const double lowest = std::min(o.score_threshold, o.confirm_score);
    boxes = net_->Detect(square, cv::Size(o.crop_px, o.crop_px),
                         o.mirror_crops ? kLowestCropScore : lowest, {dnn::kCocoSportsBall});
  }
  double best = 0.0;
  for (const dnn::DnnBox& b : boxes) {
    if (Confirms(centre_px, radius_px, b.box, o.box_size_ratio)) best = std::max(best, b.score);
  }
  return best;
}

std::vector<double> DnnBallDetector::CropScores(const cv::Mat& bgr,
                                                const std::vector<BallCandidate>& candidates,
                                                const cv::Rect& roi) const {
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "dnn ball detector: expected a BGR frame");
  const DnnBallOptions& o = options_;
  const cv::Rect area = SearchArea(bgr.size(), roi);
  std::vector<double> scores(candidates.size(), 0.0);
  // Accepted first, then weak or disc-shaped ones, then the rest, each in the detector's order.
  std::vector<size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const auto rank = [](const BallCandidate& c) {
      return c.accepted ? 0 : (c.weak || c.disc_shaped ? 1 : 2);
    };
    return rank(candidates[a]) < rank(candidates[b]);
  });
  int crops = 0;
  for (size_t i : order) {
    if (crops >= o.max_crops) break;
    const BallCandidate& c = candidates[i];
    if (!(c.radius_px > 0) || !c.centre_px.allFinite()) continue;
    const int side = CropSide(c, o);
    const cv::Rect crop(static_cast<int>(std::lround(c.centre_px.x() - 0.5 * side)),
                        static_cast<int>(std::lround(c.centre_px.y() - 0.5 * side)), side, side);
    const cv::Rect inside = crop & area;
    if (inside.empty()) continue;
    // The crop square, grey where it leaves the searched area (nothing outside it is read).
    cv::Mat square(side, side, CV_8UC3, cv::Scalar::all(kPadGrey));
    bgr(inside).copyTo(square(inside - crop.tl()));
    ++crops;
    const Eigen::Vector2d centre = c.centre_px - Eigen::Vector2d(crop.x, crop.y);
    scores[i] = SquareScore(square, centre, c.radius_px);
    if (o.mirror_crops) {
      cv::Mat mirrored;
      cv::flip(square, mirrored, 1);
      const double m =
          SquareScore(mirrored, Eigen::Vector2d(side - centre.x(), centre.y()), c.radius_px);
      scores[i] = 0.5 * (scores[i] + m);
    }
  }
  return scores;
}

AnyBallDetector::AnyBallDetector(const BallDetectorOptions& colour, const DnnBallOptions& dnn,
                                 const camera::Camera* camera, const field::FieldModel* field)
    : dnn_options_(dnn) {
  dnn_options_.Check();
  colour_spot_contrast_ = colour.small.min_contrast;
  BallDetectorOptions colour_options = colour;
  if (dnn_options_.detector == "both") {
    colour_options.small.min_contrast = dnn_options_.spot_min_contrast;
  }
  colour_ = std::make_unique<BallDetector>(colour_options, camera, field);
  if (dnn_options_.detector == "both" && dnn_options_.rescan_step_px > 0 &&
      dnn_options_.rescan_step_px < colour_options.scan_step_px) {
    colour_options.scan_step_px = dnn_options_.rescan_step_px;
    fine_colour_ = std::make_unique<BallDetector>(colour_options, camera, field);
  }
  if (dnn_options_.uses_dnn()) dnn_ = std::make_unique<DnnBallDetector>(dnn_options_);
}

std::vector<BallCandidate> AnyBallDetector::FilterDnn(std::vector<BallCandidate> cands) const {
  const BallDetectorOptions& o = colour_->options();
  const cv::Mat& mask = colour_->field_mask();
  std::erase_if(cands, [&](const BallCandidate& c) {
    if (c.radius_px < o.min_radius_px || c.radius_px > o.max_radius_px) return true;
    if (mask.empty()) return false;
    const int u = static_cast<int>(std::lround(c.centre_px.x()));
    const int v = static_cast<int>(std::lround(c.centre_px.y()));
    return u < 0 || v < 0 || u >= mask.cols || v >= mask.rows || mask.at<uint8_t>(v, u) == 0;
  });
  return cands;
}

void AnyBallDetector::DemoteFaintSpots(std::vector<BallCandidate>* candidates) const {
  for (BallCandidate& c : *candidates) {
    if (!c.small || !c.accepted || c.contrast >= colour_spot_contrast_) continue;
    c.accepted = false;
    c.disc_shaped = true;  // checked by the network after the accepted ones
    c.reason = fmt::format("a faint small spot (contrast {:.1f} < {:.1f}) the network must confirm",
                           c.contrast, colour_spot_contrast_);
  }
}

void AnyBallDetector::MeasureFieldShares(const cv::Mat& bgr, const cv::Rect& region,
                                         const std::vector<double>& confirm,
                                         std::vector<BallCandidate>* candidates) const {
  const DnnBallOptions& o = dnn_options_;
  if (o.keep_field_share <= 0 || !o.demote_unconfirmed) return;
  BallDetector::ImageFieldCache image_field;
  for (size_t i = 0; i < candidates->size(); ++i) {
    BallCandidate& c = (*candidates)[i];
    if (!c.accepted || confirm[i] >= ConfirmScore(c, o) || c.score >= o.keep_score) continue;
    c.field_share = colour_->FieldShare(bgr, region, c.centre_px, c.radius_px, o.keep_field_share,
                                        &image_field);
  }
}

std::vector<BallCandidate> AnyBallDetector::Detect(const cv::Mat& bgr,
                                                   const cv::Rect& region) const {
  if (dnn_ == nullptr) return colour_->Detect(bgr, region);
  if (!dnn_options_.uses_colour()) return FilterDnn(dnn_->Detect(bgr, region));
  std::vector<BallCandidate> whole;
  double input_scale = 1.0;
  if (dnn_options_.whole_frame) {
    whole = FilterDnn(dnn_->Detect(bgr, region));
    // Network balls come only from a searchable region, whose input scale is then defined.
    if (!whole.empty()) input_scale = dnn_->InputScale(bgr.size(), region);
  }
  // Here, not in the colour detector: only the network's confirmation reads the mark, and the
  // edge costs a pass over the frame's columns (once: both scans share it).
  const FieldBoundary boundary = colour_->OffFieldBoundary(bgr, region);
  std::vector<BallCandidate> out =
      ConfirmColour(bgr, region, *colour_, boundary, whole, input_scale, /*rescue=*/true);
  const bool none =
      std::none_of(out.begin(), out.end(), [](const BallCandidate& c) { return c.accepted; });
  if (none && fine_colour_ != nullptr) {
    out = ConfirmColour(bgr, region, *fine_colour_, boundary, whole, input_scale,
                        /*rescue=*/false);
  }
  return out;
}

std::vector<BallCandidate> AnyBallDetector::ConfirmColour(const cv::Mat& bgr,
                                                          const cv::Rect& region,
                                                          const BallDetector& colour_detector,
                                                          const FieldBoundary& boundary,
                                                          const std::vector<BallCandidate>& whole,
                                                          double input_scale, bool rescue) const {
  std::vector<BallCandidate> colour = colour_detector.Detect(bgr, region);
  MarkOffField(boundary, &colour);
  DemoteFaintSpots(&colour);
  std::vector<double> confirm = dnn_->CropScores(bgr, colour, region);
  if (!whole.empty()) {
    const std::vector<double> held = HoldingScores(colour, whole, dnn_options_, input_scale);
    for (size_t i = 0; i < confirm.size(); ++i) confirm[i] = std::max(confirm[i], held[i]);
  }
  MeasureFieldShares(bgr, region, confirm, &colour);
  return CombineBallCandidates(colour, confirm, whole, dnn_options_, rescue);
}

std::optional<BallCandidate> AnyBallDetector::FitAt(const cv::Mat& bgr, const cv::Rect& region,
                                                    const Eigen::Vector2d& centre_px,
                                                    double radius_px) const {
  if (dnn_ != nullptr && !dnn_options_.uses_colour()) return std::nullopt;
  return colour_->FitAt(bgr, region, centre_px, radius_px);
}

}  // namespace fv::detect
