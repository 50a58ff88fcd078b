#include "fieldvision/detect/ball_region.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <utility>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/detect/ball_fit.h"
#include "fieldvision/detect/lab.h"
#include "fieldvision/detect/search_area.h"
#include "fieldvision/util/error.h"

namespace fv::detect {
namespace {

using Eigen::Vector2d;

cv::Rect Grow(const cv::Rect& r, int g) {
  return {r.x - g, r.y - g, r.width + 2 * g, r.height + 2 * g};
}

// `r` widened to the right (to the left at the `cols` edge) to a multiple of 32 columns, else 16 or
// 8, where that fits in `cols`: OpenCV's morphology on 8-bit images works 32, 16 or 8 pixels at a
// time and pixel by pixel, much slower, on the rest of each row.
cv::Rect MorphologyWidth(const cv::Rect& r, int cols) {
  for (const int q : {32, 16, 8}) {
    const int w = (r.width + q - 1) / q * q;
    if (w <= cols) return {std::min(r.x, cols - w), r.y, w, r.height};
  }
  return r;
}

// m[x] = 255 where k[x] has `bit`, else 0 (x < n); the rows do not overlap, so it vectorises.
void BitMaskRow(const uint8_t* __restrict k, int n, uint8_t bit, uint8_t* __restrict m) {
  for (int x = 0; x < n; ++x) m[x] = (k[x] & bit) != 0 ? 255 : 0;
}

// The class bits of `table` of every pixel of `bgr_window` in `cls` (CV_8U) and its `bit` class
// in `raw` (CV_8U, 255 = in the class), row by row.
void ClassMasks(const cv::Mat& bgr_window, const ColourTable& table, uint8_t bit, cv::Mat* raw,
                cv::Mat* cls) {
  raw->create(bgr_window.size(), CV_8U);
  cls->create(bgr_window.size(), CV_8U);
  for (int y = 0; y < bgr_window.rows; ++y) {
    uint8_t* k = cls->ptr<uint8_t>(y);
    table.ClassifyRow<1>(bgr_window.ptr<uint8_t>(y), bgr_window.cols, 1, k);
    BitMaskRow(k, bgr_window.cols, bit, raw->ptr<uint8_t>(y));
  }
}

// The window's CIELAB (cv::COLOR_BGR2Lab, converted pixel by pixel), converted only where asked
// for: most of the window is never read. Each row's converted pixels are one run of columns; what
// a request adds to them is gathered and converted in one call (the conversion of a pixel does not
// depend on its neighbours).
class LabWindow {
 public:
  explicit LabWindow(const cv::Mat& bgr_window)
      : bgr_(bgr_window),
        lab_(bgr_window.size(), CV_8UC3),
        lo_(bgr_window.rows, 0),
        hi_(bgr_window.rows, 0) {}
  // Valid inside every span passed to NeedSpans.
  const cv::Mat& lab() const { return lab_; }
  // Columns spans[y].first..spans[y].second-1 of each row y of `rect` (rect's coordinates).
  void NeedSpans(const cv::Rect& rect, const std::vector<std::pair<int, int>>& spans) {
    pieces_.clear();
    for (int y = 0; y < rect.height; ++y) {
      AddRow(rect.y + y, rect.x + spans[y].first, rect.x + spans[y].second);
    }
    ConvertPieces();
  }

 private:
  struct Piece {
    int y, x0, x1;
  };
  // Columns x0..x1-1 of row y, less those converted: the row's run grows to cover them.
  void AddRow(int y, int x0, int x1) {
    if (x0 >= x1) return;
    if (lo_[y] >= hi_[y]) {
      pieces_.push_back({y, x0, x1});
      lo_[y] = x0;
      hi_[y] = x1;
      return;
    }
    if (x0 < lo_[y]) {
      pieces_.push_back({y, x0, lo_[y]});
      lo_[y] = x0;
    }
    if (x1 > hi_[y]) {
      pieces_.push_back({y, hi_[y], x1});
      hi_[y] = x1;
    }
  }
  void ConvertPieces() {
    int total = 0;
    for (const Piece& p : pieces_) total += p.x1 - p.x0;
    if (total == 0) return;
    gathered_.create(1, total, CV_8UC3);
    uint8_t* g = gathered_.ptr<uint8_t>(0);
    for (const Piece& p : pieces_) {
      const size_t n = 3 * static_cast<size_t>(p.x1 - p.x0);
      std::memcpy(g, bgr_.ptr<uint8_t>(p.y) + 3 * static_cast<ptrdiff_t>(p.x0), n);
      g += n;
    }
    BgrToLab(gathered_, &converted_);
    const uint8_t* c = converted_.ptr<uint8_t>(0);
    for (const Piece& p : pieces_) {
      const size_t n = 3 * static_cast<size_t>(p.x1 - p.x0);
      std::memcpy(lab_.ptr<uint8_t>(p.y) + 3 * static_cast<ptrdiff_t>(p.x0), c, n);
      c += n;
    }
  }
  cv::Mat bgr_, lab_;
  std::vector<int> lo_, hi_;  // each row's converted columns lo..hi-1 (none when lo >= hi)
  std::vector<Piece> pieces_;
  cv::Mat gathered_, converted_;
};

// The 8-connected components of a binary mask (CV_8U, non-zero set) as runs of set pixels, row
// by row: what cv::connectedComponents finds, without a label image.
struct MaskComponents {
  struct Run {
    int y, x0, x1;  // x0..x1 inclusive
  };
  std::vector<Run> runs;
  std::vector<int> component;  // of each run, 0..count-1
  int count = 0;
};

int FindRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

MaskComponents LabelMask(const cv::Mat& mask) {
  MaskComponents mc;
  std::vector<int> parent;
  int prev_begin = 0, prev_end = 0;
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y);
    const int cur_begin = static_cast<int>(mc.runs.size());
    for (int x = 0; x < mask.cols;) {
      // Clear pixels are skipped 8 at a time (most of a window is clear).
      if (x + 8 <= mask.cols) {
        uint64_t word;
        std::memcpy(&word, m + x, sizeof(word));
        if (word == 0) {
          x += 8;
          continue;
        }
      }
      if (m[x] == 0) {
        ++x;
        continue;
      }
      const int x0 = x;
      while (x + 1 < mask.cols && m[x + 1] != 0) ++x;
      mc.runs.push_back({y, x0, x});
      parent.push_back(static_cast<int>(parent.size()));
      ++x;
    }
    const int cur_end = static_cast<int>(mc.runs.size());
    // Runs of consecutive rows touch (8-connected) when they overlap or meet at a corner.
    for (int a = prev_begin, b = cur_begin; a < prev_end && b < cur_end;) {
      const auto& p = mc.runs[a];
      const auto& c = mc.runs[b];
      if (p.x0 <= c.x1 + 1 && c.x0 <= p.x1 + 1) {
        const int ra = FindRoot(parent, a), rb = FindRoot(parent, b);
        if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
      }
      if (p.x1 < c.x1) {
        ++a;
      } else {
        ++b;
      }
    }
    prev_begin = cur_begin;
    prev_end = cur_end;
  }
  mc.component.resize(mc.runs.size());
  std::vector<int> id(mc.runs.size(), -1);
  for (size_t i = 0; i < mc.runs.size(); ++i) {
    int& c = id[FindRoot(parent, static_cast<int>(i))];
    if (c < 0) c = mc.count++;
    mc.component[i] = c;
  }
  return mc;
}

// The mask (CV_8U, 255 set) of the components of `mc` with `chosen` set, `size` large.
cv::Mat PaintComponents(const MaskComponents& mc, const std::vector<char>& chosen,
                        const cv::Size& size) {
  cv::Mat out(size, CV_8U, cv::Scalar(0));
  for (size_t i = 0; i < mc.runs.size(); ++i) {
    if (!chosen[mc.component[i]]) continue;
    const auto& run = mc.runs[i];
    uint8_t* m = out.ptr<uint8_t>(run.y);
    std::fill(m + run.x0, m + run.x1 + 1, uint8_t{255});
  }
  return out;
}

// The components of `mask` (window coordinates) near the seed, gathered twice (fragments of a
// printed ball).
cv::Mat GatherComponents(const cv::Mat& mask, const cv::Rect& seed, double gather_fraction,
                         cv::Rect* bounds) {
  const MaskComponents mc = LabelMask(mask);
  const int n = mc.count;
  std::vector<cv::Rect> boxes(n);
  std::vector<char> has(n, 0);
  for (size_t i = 0; i < mc.runs.size(); ++i) {
    const auto& run = mc.runs[i];
    const cv::Rect r(run.x0, run.y, run.x1 - run.x0 + 1, 1);
    const int c = mc.component[i];
    boxes[c] = has[c] ? (boxes[c] | r) : r;
    has[c] = 1;
  }
  std::vector<char> chosen(n, 0);
  cv::Rect reach = seed;
  cv::Rect box;
  for (int round = 0; round < 2; ++round) {
    const double r = 0.5 * std::max(reach.width, reach.height);
    const cv::Rect grown = Grow(reach, static_cast<int>(std::ceil(gather_fraction * r)) + 2);
    for (int i = 0; i < n; ++i) {
      const cv::Rect& b = boxes[i];
      // The first round takes what touches the seed itself, the second what is near it.
      const cv::Rect& target = round == 0 ? seed : grown;
      if (!chosen[i] && (b & target).area() > 0) {
        chosen[i] = 1;
        box = box.area() > 0 ? (box | b) : b;
      }
    }
    if (box.area() == 0) break;
    reach = box;
  }
  *bounds = box;
  return PaintComponents(mc, chosen, mask.size());
}

// RANSAC for the circle of a partly hidden disc: an occluder's edge lies inside the true circle,
// nothing of the disc lies outside it, so points beyond the inlier band count against a
// hypothesis (score = inliers - outside). Deterministic draws; FitCircle refines the winner with
// the band thr outside the circle and thr_in inside it.
bool OuterCircle(const std::vector<Vector2d>& pts, double thr, double thr_in, int iterations,
                 Vector2d* centre, double* radius, std::vector<char>* inlier) {
  const int n = static_cast<int>(pts.size());
  if (n < 3) return false;
  uint64_t state = 0x2545F4914F6CDD1Dull ^ static_cast<uint64_t>(n);
  auto next = [&](int m) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<int>((state >> 33) % static_cast<uint64_t>(m));
  };
  int best = -n;
  Vector2d best_c = Vector2d::Zero();
  double best_r = 0;
  for (int it = 0; it < iterations; ++it) {
    const int i = next(n), j = next(n), k = next(n);
    if (i == j || j == k || i == k) continue;
    Vector2d cc;
    double r = 0;
    if (!CircleFrom3(pts[i], pts[j], pts[k], &cc, &r)) continue;
    // A hypothesis that cannot beat the best even with every remaining point an inlier stops.
    int score = 0, left = n;
    for (const auto& p : pts) {
      if (score + left <= best) break;
      const double e = (p - cc).norm() - r;
      score += std::abs(e) < thr ? 1 : (e > 0 ? -1 : 0);
      --left;
    }
    if (left == 0 && score > best) {
      best = score;
      best_c = cc;
      best_r = r;
    }
  }
  if (best < 3) return false;
  *centre = best_c;
  *radius = best_r;
  return FitCircle(pts, thr, centre, radius, inlier, thr_in);
}

}  // namespace

void BallRegionOptions::Check() const {
  CheckInRange(gather_fraction, 0.0, 3.0, "BallRegionOptions.gather_fraction");
  CheckInRange(close_fraction, 0.0, 1.0, "BallRegionOptions.close_fraction");
  CheckInRange(grow_fraction, 0.0, 2.0, "BallRegionOptions.grow_fraction");
  CheckPositive(hull_tolerance_px, "BallRegionOptions.hull_tolerance_px");
  CheckPositive(inlier_px, "BallRegionOptions.inlier_px");
  FV_REQUIRE(inside_share > 0.0 && inside_share <= 1.0,
             "BallRegionOptions.inside_share must be in (0, 1] (got {})", inside_share);
  CheckInRange(hidden_value, 0, 255, "BallRegionOptions.hidden_value");
  CheckInRange(min_seen, 0.1, 1.0, "BallRegionOptions.min_seen");
  CheckInRange(well_seen, min_seen, 1.0, "BallRegionOptions.well_seen");
  CheckInRange(min_partly_seen_rise, -1.0, 1.0, "BallRegionOptions.min_partly_seen_rise");
  CheckInRange(own_reach, 0.0, 2.0, "BallRegionOptions.own_reach");
  CheckInRange(own_share, 0.0, 1.0, "BallRegionOptions.own_share");
  CheckNonNegative(own_max_delta_e, "BallRegionOptions.own_max_delta_e");
  FV_REQUIRE(ring_inner >= 1.0 && ring_outer > ring_inner,
             "BallRegionOptions: need 1 <= ring_inner < ring_outer (got {}, {})", ring_inner,
             ring_outer);
}

std::string BallRegion::Summary() const {
  if (!ok) return "no region: " + failure;
  return fmt::format(
      "centre ({:.2f}, {:.2f}) px, radius {:.2f} px, arc {:.0f} %, fill {:.0f} %, spill {:.0f} %, "
      "leak {:.0f} %, purity {:.0f} %, contrast {:.0f}, solidity {:.2f}, {}/{} outline points, "
      "rms {:.2f} px, seen {:.0f} % (rise {:.2f})",
      centre_px.x(), centre_px.y(), radius_px, 100 * arc_cover, 100 * fill, 100 * spill, 100 * leak,
      100 * purity, contrast, solidity, inliers, outline_points, rms_px, 100 * seen, seen_rise);
}

namespace {

// A histogram of CIELAB colours (OpenCV 8-bit scale): medians in linear time.
struct LabHistogram {
  std::array<std::array<int, 256>, 3> hist{};
  int n = 0;
  void Add(const uint8_t* lab_px) {
    ++n;
    for (int ch = 0; ch < 3; ++ch) ++hist[ch][lab_px[ch]];
  }
  // The median colour; false if empty.
  bool Median(Eigen::Vector3d* out) const {
    if (n == 0) return false;
    for (int ch = 0; ch < 3; ++ch) {
      int seen = 0, v = 0;
      while (v < 255 && (seen += hist[ch][v]) * 2 < n) ++v;
      (*out)[ch] = v;
    }
    return true;
  }
  // util::Median of the channel's values (the mean of the two middle ones for an even count).
  double ChannelMedian(int ch) const {
    const double pos = 0.5 * static_cast<double>(n - 1);
    const int lo = static_cast<int>(std::floor(pos));
    const int hi = std::min(lo + 1, n - 1);
    const double v_lo = Ranked(ch, lo);
    if (hi == lo) return v_lo;
    return v_lo + (pos - static_cast<double>(lo)) * (Ranked(ch, hi) - v_lo);
  }
  // The channel's value of rank k (0: the smallest).
  double Ranked(int ch, int k) const {
    int seen = 0, v = 0;
    while (v < 255 && (seen += hist[ch][v]) <= k) ++v;
    return v;
  }
};

// The region grown by its own colour (BallRegionOptions::own_reach; r its radius): seeded region
// growing (Adams & Bischof, PAMI 1994) against the surroundings' median colour. Distances to the
// region come from one distance transform; colour distances are CIELAB Delta E 1976, squared.
// The ring's outer distance and the reach of GrowByOwnColourIn.
float OwnRingOut(float r) { return std::max(3.0f, 0.6f * r); }
float OwnReach(const BallRegionOptions& o, float r) {
  return std::max(1.0f, static_cast<float>(o.own_reach) * r);
}

// `dist`: the distance transform of the region's complement; `spans`: on each row, the columns
// from the first to the last pixel whose distance is at most max(OwnRingOut(r), OwnReach(o, r)),
// the only ones read.
void GrowByOwnColourIn(const cv::Mat& lab, const cv::Mat& raw, const cv::Mat& dist,
                       const std::vector<std::pair<int, int>>& spans, const BallRegionOptions& o,
                       float r, cv::Mat* region) {
  // The region's ball-class pixels (all of its pixels when none is) and the ring's pixels
  // outside the class, in one pass.
  const float ring_in = std::max(1.0f, 0.3f * r), ring_out = OwnRingOut(r);
  LabHistogram own_class, own_all, ring;
  for (int y = 0; y < lab.rows; ++y) {
    const uint8_t* l = lab.ptr<uint8_t>(y);
    const float* d = dist.ptr<float>(y);
    const uint8_t* m = raw.ptr<uint8_t>(y);
    for (int x = spans[y].first; x < spans[y].second; ++x) {
      const uint8_t* lab_px = l + 3 * static_cast<ptrdiff_t>(x);
      if (d[x] == 0) {
        own_all.Add(lab_px);
        if (m[x] != 0) own_class.Add(lab_px);
      } else if (d[x] > ring_in && d[x] <= ring_out && m[x] == 0) {
        ring.Add(lab_px);
      }
    }
  }
  Eigen::Vector3d own, around;
  const bool has_own = own_class.Median(&own) || own_all.Median(&own);
  if (!has_own || !ring.Median(&around)) return;
  // CIELAB with L on its own scale (OpenCV's 8-bit L is L * 255 / 100): squared norms are
  // Delta E 1976 squared.
  const Eigen::Vector3f scale(100.0f / 255.0f, 1.0f, 1.0f);
  const Eigen::Vector3f own_f = own.cast<float>().cwiseProduct(scale);
  const Eigen::Vector3f around_f = around.cast<float>().cwiseProduct(scale);
  const float limit2 =
      std::min(static_cast<float>(o.own_max_delta_e * o.own_max_delta_e),
               static_cast<float>(o.own_share * o.own_share) * (own_f - around_f).squaredNorm());
  const float reach = OwnReach(o, r);
  cv::Mat joined = region->clone();
  for (int y = 0; y < lab.rows; ++y) {
    const uint8_t* l = lab.ptr<uint8_t>(y);
    const float* d = dist.ptr<float>(y);
    uint8_t* j = joined.ptr<uint8_t>(y);
    for (int x = spans[y].first; x < spans[y].second; ++x) {
      if (d[x] == 0 || d[x] > reach) continue;
      const uint8_t* lab_px = l + 3 * static_cast<ptrdiff_t>(x);
      const Eigen::Vector3f p =
          Eigen::Vector3f(lab_px[0], lab_px[1], lab_px[2]).cwiseProduct(scale);
      const float d_own2 = (p - own_f).squaredNorm();
      if (d_own2 < limit2 && d_own2 < (p - around_f).squaredNorm()) j[x] = 255;
    }
  }
  // Keep what is connected to the region.
  const MaskComponents mc = LabelMask(joined);
  std::vector<char> keep(mc.count, 0);
  for (size_t i = 0; i < mc.runs.size(); ++i) {
    const auto& run = mc.runs[i];
    const uint8_t* m = region->ptr<uint8_t>(run.y);
    keep[mc.component[i]] |= std::any_of(m + run.x0, m + run.x1 + 1, [](uint8_t v) { return v; });
  }
  PaintComponents(mc, keep, region->size()).copyTo(*region);
}

// GrowByOwnColourIn on the part of the window within reach of the region (and its ring).
// `*extent` holds every pixel of the region, before and after.
void GrowByOwnColour(LabWindow* lab, const cv::Mat& raw, const BallRegionOptions& o,
                     cv::Mat* region, cv::Rect* extent) {
  const cv::Rect box = cv::boundingRect((*region)(*extent)) + extent->tl();
  if (box.area() == 0) return;
  const float r = 0.5f * static_cast<float>(std::max(box.width, box.height));
  const int margin =
      static_cast<int>(std::ceil(std::max({3.0f, 0.6f * r, static_cast<float>(o.own_reach) * r}))) +
      2;
  const cv::Rect sub = Grow(box, margin) & cv::Rect(0, 0, region->cols, region->rows);
  cv::Mat part = (*region)(sub);
  cv::Mat outside, dist;  // distance to the region, pixels (0 inside it)
  cv::bitwise_not(part, outside);
  cv::distanceTransform(outside, dist, cv::DIST_L2, cv::DIST_MASK_3);
  // Nothing farther than the ring's outer distance and the reach is read: on each row, the
  // columns from the first to the last pixel within them.
  const float limit = std::max(OwnRingOut(r), OwnReach(o, r));
  std::vector<std::pair<int, int>> spans(sub.height);
  for (int y = 0; y < sub.height; ++y) {
    const float* d = dist.ptr<float>(y);
    int x0 = 0, x1 = sub.width;
    while (x0 < x1 && !(d[x0] <= limit)) ++x0;
    while (x1 > x0 && !(d[x1 - 1] <= limit)) --x1;
    spans[y] = {x0, x1};
  }
  lab->NeedSpans(sub, spans);
  GrowByOwnColourIn(lab->lab()(sub), raw(sub), dist, spans, o, r, &part);
  *extent = sub;
}

// The gathered region grown through the widened class near its core and closed (print, seams);
// empty when no ball-coloured pixel touches the seed. `grow`: the widened class's bit in each
// pixel's class bits (`cls`, the window's own when given, else classified by `grow.table`).
// `*extent` (window coordinates) holds every pixel of the region: only that part is scanned.
struct GrowClass {
  const ColourTable* table = nullptr;  // null: no growing
  uint8_t bit = 0;
  const cv::Mat* cls = nullptr;  // the window's class bits from grow.table, or null
};
cv::Mat GrowAndCloseRegion(const cv::Mat& bgr_window, const cv::Mat& raw, const GrowClass& grow,
                           LabWindow* lab, const cv::Rect& seed, const BallRegionOptions& o,
                           cv::Rect* extent) {
  cv::Rect bounds;
  cv::Mat region = GatherComponents(raw, seed, o.gather_fraction, &bounds);
  if (bounds.area() == 0) return {};
  *extent = bounds;
  const double r_region = 0.5 * std::max(bounds.width, bounds.height);
  if (grow.table != nullptr) {
    // Hysteresis with a reach: widened-class pixels join only near the core (a shaded rim, a
    // pale cap), so a neighbour of a similar colour is not taken in. Nothing farther than the
    // reach from the gathered bounds can join: only that part is dilated and classified.
    const int reach = std::max(1, static_cast<int>(std::lround(o.grow_fraction * r_region)));
    const cv::Rect sub = Grow(bounds, reach) & cv::Rect(0, 0, raw.cols, raw.rows);
    // The widened class's pixels not yet in the region, and their bounds: the dilation is needed
    // only there (within reach of them), and not at all when there are none.
    cv::Mat cand(sub.size(), CV_8U);
    int x0 = sub.width, x1 = -1, y0 = sub.height, y1 = -1;
    for (int y = 0; y < sub.height; ++y) {
      const uint8_t* m = region.ptr<uint8_t>(sub.y + y) + sub.x;
      uint8_t* c = cand.ptr<uint8_t>(y);
      if (grow.cls != nullptr) {
        std::memcpy(c, grow.cls->ptr<uint8_t>(sub.y + y) + sub.x, sub.width);
      } else {
        grow.table->ClassifyRow<1>(
            bgr_window.ptr<uint8_t>(sub.y + y) + 3 * static_cast<ptrdiff_t>(sub.x), sub.width, 1,
            c);
      }
      for (int x = 0; x < sub.width; ++x) {
        c[x] = m[x] == 0 && (c[x] & grow.bit) != 0;
        if (c[x] != 0) {
          x0 = std::min(x0, x);
          x1 = std::max(x1, x);
          y0 = std::min(y0, y);
          y1 = y;
        }
      }
    }
    if (x1 >= 0) {
      const cv::Rect cbox = cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1) + sub.tl();
      // The dilation of a part of the region (not BORDER_ISOLATED) reads the region around the
      // part too: only cbox's pixels (widened to a fast width) are computed.
      const cv::Rect nbox = MorphologyWidth(cbox, raw.cols);
      cv::Mat near;
      cv::dilate(
          region(nbox), near,
          cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * reach + 1, 2 * reach + 1)));
      for (int y = cbox.y; y < cbox.br().y; ++y) {
        const uint8_t* c = cand.ptr<uint8_t>(y - sub.y);
        const uint8_t* nr = near.ptr<uint8_t>(y - nbox.y);
        uint8_t* m = region.ptr<uint8_t>(y);
        for (int x = cbox.x; x < cbox.br().x; ++x) {
          if (c[x - sub.x] != 0 && nr[x - nbox.x] != 0) m[x] = 255;
        }
      }
    }
    *extent = sub;
  }
  if (o.own_reach > 0) GrowByOwnColour(lab, raw, o, &region, extent);
  const int k = std::min(4, static_cast<int>(std::lround(o.close_fraction * r_region)));
  if (k >= 1) {
    // Closing sets nothing outside the region's bounds (the element's middle row and column
    // span +-k), and k + 1 out is enough: the dilation is exact within k of the bounds (no region
    // beyond them), and each pixel whose erosion reaches past the part's border (eroded as if
    // set) also reaches, on its own row or column, a pixel k + 1 out that the dilation left
    // clear, unless the window's edge clips that side (as it clips a wider part).
    // A part with the full k + 1 columns on both sides may be widened further (to a width that
    // OpenCV's morphology does fast) within the window: the same region (compared on 400000
    // random masks); one clipped by the window's side is left as it is.
    const cv::Rect bounds_now = cv::boundingRect(region(*extent)) + extent->tl();
    const cv::Rect sub = Grow(bounds_now, k + 1) & cv::Rect(0, 0, region.cols, region.rows);
    const bool full_sides =
        sub.x == bounds_now.x - (k + 1) && sub.br().x == bounds_now.br().x + k + 1;
    const cv::Rect wide = full_sides ? MorphologyWidth(sub, region.cols) : sub;
    cv::Mat part = region(wide).clone();
    cv::morphologyEx(part, part, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * k + 1, 2 * k + 1)));
    part.copyTo(region(wide));
    *extent = sub;
  }
  return region;
}

// The region's largest outer contour and the region it bounds, filled (holes from a print or a
// highlight belong to the ball); false when there is no outline. `extent` holds every pixel of
// the region: only that part is traced and filled.
bool LargestFilledOutline(const cv::Mat& region, const cv::Rect& extent,
                          std::vector<cv::Point>* contour, cv::Mat* filled) {
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(region(extent), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, extent.tl());
  if (contours.empty()) return false;
  const auto largest =
      std::max_element(contours.begin(), contours.end(), [](const auto& a, const auto& b) {
        return cv::contourArea(a) + a.size() < cv::contourArea(b) + b.size();
      });
  *filled = cv::Mat(region.size(), CV_8U, cv::Scalar(0));
  cv::Mat part = (*filled)(extent);
  // cv::fillPoly fills one contour as cv::drawContours(FILLED) does (compared on 10 M random
  // contours), without its conversion to the old contour tree.
  *contour = std::move(*largest);
  const cv::Point* points = contour->data();
  const int count = static_cast<int>(contour->size());
  cv::fillPoly(part, &points, &count, 1, 255, cv::LINE_8, 0, -extent.tl());
  return true;
}

// The squared distance of `p` from the segment a..b.
double SegmentDistance2(const cv::Point& p, const cv::Point& a, const cv::Point& b) {
  const double dx = b.x - a.x, dy = b.y - a.y, px = p.x - a.x, py = p.y - a.y;
  const double t = px * dx + py * dy, len2 = dx * dx + dy * dy;
  if (t <= 0) return px * px + py * py;
  if (t >= len2) return (p.x - b.x) * double(p.x - b.x) + (p.y - b.y) * double(p.y - b.y);
  const double cross = px * dy - py * dx;
  return cross * cross / len2;
}

// Points of `contour` (window coordinates) on its convex hull (`hull_index`: its vertices'
// indices in `contour`, as cv::convexHull gives them) within `tolerance_px`, in image coordinates,
// leaving out those on the border of `lim` (a clipped outline). The distance is
// cv::pointPolygonTest's (the least over the hull's edges), but a point that is a hull vertex, or
// is clearly within the tolerance of the hull edge between the vertices before and after it on
// the contour (an upper bound of that least distance), is taken without it.
std::vector<Vector2d> ConvexOutlinePoints(const std::vector<cv::Point>& contour,
                                          const std::vector<int>& hull_index,
                                          const std::vector<cv::Point>& hull,
                                          const cv::Point& window_tl, const cv::Rect& lim,
                                          double tolerance_px) {
  const int n = static_cast<int>(contour.size());
  // The hull vertex at or before (after) each contour point, cyclically, and each vertex's place
  // on the hull.
  const int h = static_cast<int>(hull_index.size());
  std::vector<int> before(n, -1), after(n, -1), place(n, -1);
  if (h > 0) {
    for (int k = 0; k < h; ++k) {
      const int i = hull_index[k];
      before[i] = after[i] = i;
      place[i] = k;
    }
    int last = *std::max_element(hull_index.begin(), hull_index.end());
    for (int i = 0; i < n; ++i) last = before[i] = before[i] >= 0 ? before[i] : last;
    int next = *std::min_element(hull_index.begin(), hull_index.end());
    for (int i = n - 1; i >= 0; --i) next = after[i] = after[i] >= 0 ? after[i] : next;
  }
  // Well inside the tolerance (the margin covers rounding).
  const double sure2 = tolerance_px * tolerance_px * (1 - 1e-9);
  std::vector<Vector2d> pts;
  for (int i = 0; i < n; ++i) {
    const cv::Point& p = contour[i];
    const int gx = p.x + window_tl.x, gy = p.y + window_tl.y;
    const bool at_border =
        gx <= lim.x || gy <= lim.y || gx >= lim.x + lim.width - 1 || gy >= lim.y + lim.height - 1;
    if (at_border) continue;
    bool near = false;
    if (h > 0) {
      // The vertices before and after the point make a hull edge (not a chord) when they are
      // next to each other on the hull.
      const int step = (place[after[i]] - place[before[i]] + h) % h;
      near = before[i] == i || ((step <= 1 || step == h - 1) &&
                                SegmentDistance2(p, contour[before[i]], contour[after[i]]) < sure2);
    }
    if (!near) {
      near = std::abs(cv::pointPolygonTest(hull, cv::Point2f(p.x, p.y), true)) <= tolerance_px;
    }
    if (near) pts.emplace_back(gx, gy);
  }
  return pts;
}

// How the outline points sit on the circle (c, r): inlier residuals, points beyond the band and
// which of `bins` angle bins hold an inlier.
struct OutlineOnCircle {
  double sum_sq = 0;
  int inliers = 0;
  int outside = 0;
  std::vector<char> bin_hit;
};

OutlineOnCircle MeasureOutlineOnCircle(const std::vector<Vector2d>& pts,
                                       const std::vector<char>& inl, const Vector2d& c, double r,
                                       double thr, int bins) {
  OutlineOnCircle m;
  m.bin_hit.assign(bins, 0);
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!inl[i]) {
      m.outside += (pts[i] - c).norm() + 0.5 > r + thr;
      continue;
    }
    const Vector2d d = pts[i] - c;
    const double e = d.norm() + 0.5 - r;
    m.sum_sq += e * e;
    ++m.inliers;
    double th = std::atan2(d.y(), d.x());
    if (th < 0) th += 2 * M_PI;
    m.bin_hit[std::min(bins - 1, static_cast<int>(th / (2 * M_PI) * bins))] = 1;
  }
  return m;
}

// Whether the pixel is dark enough to hide the ball (BallRegionOptions::hidden_value).
bool IsDark(const cv::Mat& bgr, int x, int y, int hidden_value) {
  const uint8_t* p = bgr.ptr<uint8_t>(y) + 3 * static_cast<ptrdiff_t>(x);
  return std::max({p[0], p[1], p[2]}) < hidden_value;
}

// Angle bins of the circle that are seen (`known`: not outside `lim`, not hidden: every pixel
// just beyond it, 1.1..1.3 r, dark), those of them with outline (`hit`) and how far up the seen
// part lies (`rise`: the mean of -sin over the seen bins, image rows down; 1: only the top).
void CountSeenBins(const cv::Mat& bgr, const Vector2d& c, double r,
                   const std::vector<char>& bin_hit, const cv::Rect& lim, int hidden_value,
                   int* known, int* hit, double* rise) {
  const int bins = static_cast<int>(bin_hit.size());
  *known = 0;
  *hit = 0;
  double rise_sum = 0.0;
  for (int b = 0; b < bins; ++b) {
    const double th = 2 * M_PI * (b + 0.5) / bins;
    const double x = c.x() + r * std::cos(th), y = c.y() + r * std::sin(th);
    bool visible = x >= lim.x + 1 && y >= lim.y + 1 && x <= lim.x + lim.width - 2 &&
                   y <= lim.y + lim.height - 2;
    if (visible && hidden_value > 0 && !bin_hit[b]) {
      bool all_dark = true, any = false;
      for (const double f : {1.1, 1.2, 1.3}) {
        const int px = static_cast<int>(std::lround(c.x() + (f * r + 1) * std::cos(th)));
        const int py = static_cast<int>(std::lround(c.y() + (f * r + 1) * std::sin(th)));
        if (!lim.contains({px, py})) continue;
        any = true;
        all_dark = all_dark && IsDark(bgr, px, py, hidden_value);
      }
      visible = !(any && all_dark);
    }
    *known += visible || bin_hit[b];
    *hit += bin_hit[b];
    if (visible || bin_hit[b]) rise_sum -= std::sin(th);
  }
  *rise = *known > 0 ? rise_sum / *known : 0.0;
}

// Why a circle seen as `region` says (seen, partly_seen, seen_rise) cannot be judged ("" when it
// can): too little of it seen, or under half of it and not its top or not its centre.
std::string SeenProblem(const BallRegion& region, const Vector2d& c, const cv::Rect& lim,
                        const BallRegionOptions& o) {
  if (region.seen < o.min_seen) return "most of the outline is outside the image or hidden";
  if (!region.partly_seen) return "";
  if (region.seen_rise < o.min_partly_seen_rise) {
    return fmt::format("under half the outline seen, and not its top (rise {:.2f} < {:.2f})",
                       region.seen_rise, o.min_partly_seen_rise);
  }
  if (!cv::Rect2d(lim).contains(cv::Point2d(c.x(), c.y()))) {
    return "under half the outline seen, its centre outside the image (or the area searched)";
  }
  return "";
}

// The convex outline's second largest distance from the centre, in radii (one stray pixel does
// not count, a corner's few do).
double OutlineExtent(const std::vector<Vector2d>& pts, const Vector2d& c, double r) {
  std::vector<double> rel;
  rel.reserve(pts.size());
  for (const auto& p : pts) rel.push_back(((p - c).norm() + 0.5) / r);
  std::nth_element(rel.begin(), rel.begin() + 1, rel.end(), std::greater<>());
  return rel.size() >= 2 ? rel[1] : rel[0];
}

// Fill, spill, leak, purity and contrast of the circle (c, r) over `window` (`lab` its CIELAB):
// `filled` is the closed, filled region, `raw` the ball class (window coordinates); `area` the
// region's area. Only the pixels in `read` (window coordinates) count: those within the ring's
// outer radius and those of the region.
void MeasureRegionColours(const cv::Mat& bgr, const cv::Rect& window, const cv::Mat& lab,
                          const cv::Mat& filled, const cv::Mat& raw, const cv::Mat& cls,
                          const cv::Rect& read, const Vector2d& c, double r, double area,
                          const BallRegionOptions& o, uint8_t field_bit, uint8_t grass_bit,
                          BallRegion* out) {
  LabHistogram disc_lab, core_lab, ring_lab;
  const double r_core = 0.8 * r;
  const double r_spill = 1.25 * r + 1.0, ri = o.ring_inner * r, ro = o.ring_outer * r;
  long long disc = 0, disc_in = 0, spill = 0, ring = 0, ring_ball = 0, ring_field = 0,
            ring_grass = 0, ring_dark = 0, pure = 0;
  for (int y = read.y; y < read.y + read.height; ++y) {
    const uint8_t* f = filled.ptr<uint8_t>(y);
    const uint8_t* m = raw.ptr<uint8_t>(y);
    const double dy = window.y + y - c.y();
    for (int x = read.x; x < read.x + read.width; ++x) {
      const double dx = window.x + x - c.x();
      const double d = std::sqrt(dx * dx + dy * dy);
      if (d < r) {
        // A dark pixel not in the region hides the ball there (see hidden_value).
        if (f[x] != 0 || o.hidden_value <= 0 ||
            !IsDark(bgr, window.x + x, window.y + y, o.hidden_value)) {
          ++disc;
          disc_in += f[x] != 0;
        }
      } else if (d > r_spill) {
        spill += f[x] != 0;
      }
      if (d >= ri && d < ro) {
        ++ring;
        ring_ball += m[x] != 0;
        if (m[x] == 0) {  // what is around the ball, not more of its colour (that is leak)
          ring_lab.Add(lab.ptr<uint8_t>(y) + 3 * static_cast<ptrdiff_t>(x));
          if (o.hidden_value > 0 && IsDark(bgr, window.x + x, window.y + y, o.hidden_value)) {
            ++ring_dark;
          } else {
            ring_field += (cls.ptr<uint8_t>(y)[x] & field_bit) != 0;
            ring_grass += (cls.ptr<uint8_t>(y)[x] & grass_bit) != 0;
          }
        }
      } else if (d < r_core) {
        const uint8_t* l = lab.ptr<uint8_t>(y) + 3 * static_cast<ptrdiff_t>(x);
        // The ball's own colour (not its print, shadow or a hidden part), else the whole core.
        (m[x] != 0 ? disc_lab : core_lab).Add(l);
      }
      pure += f[x] != 0 && m[x] != 0;
    }
  }
  out->fill = disc > 0 ? double(disc_in) / disc : 0.0;
  out->spill = spill / (M_PI * r * r);
  out->leak = ring > 0 ? double(ring_ball) / ring : 0.0;
  // Dark pixels around the ball (a robot, a shadow) hide the field; at most half the ring.
  const long long ring_seen = std::max(ring - ring_dark, (ring + 1) / 2);
  out->field_ring = ring_seen > 0 ? double(ring_field) / ring_seen : 0.0;
  out->grass_ring = ring_seen > 0 ? double(ring_grass) / ring_seen : 0.0;
  out->purity = area > 0 ? pure / area : 0.0;
  const LabHistogram& disc_h = disc_lab.n > 0 ? disc_lab : core_lab;
  if (disc_h.n > 0 && ring_lab.n > 0) {
    // OpenCV's 8-bit Lab: L * 255 / 100, a + 128, b + 128.
    const auto median_lab = [](const LabHistogram& h) {
      return Eigen::Vector3d(h.ChannelMedian(0) * 100.0 / 255.0, h.ChannelMedian(1) - 128.0,
                             h.ChannelMedian(2) - 128.0);
    };
    const Eigen::Vector3d disc_c = median_lab(disc_h), ring_c = median_lab(ring_lab);
    out->contrast = (disc_c - ring_c).norm();
    // Delta H^2 = Delta a^2 + Delta b^2 - Delta C^2.
    out->ring_chroma = ring_c.tail<2>().norm();
    out->ring_lightness = ring_c.x();
    out->chroma_contrast = disc_c.tail<2>().norm() - out->ring_chroma;
    const double dc = out->chroma_contrast;
    out->hue_contrast =
        std::sqrt(std::max(0.0, (disc_c - ring_c).tail<2>().squaredNorm() - dc * dc));
  }
}

}  // namespace

BallRegion AnalyseBallRegion(const cv::Mat& bgr, const ColourTable& table, uint8_t ball_bit,
                             const cv::Rect& seed_box, const cv::Rect& limit,
                             const BallRegionOptions& o, const ColourTable* grow_table,
                             uint8_t grow_bit) {
  BallRegion out;
  const cv::Rect lim = SearchArea(bgr.size(), limit);
  const double r0 = 0.5 * std::max(seed_box.width, seed_box.height);
  const cv::Rect window = Grow(seed_box, static_cast<int>(std::ceil(2.5 * r0)) + 6) & lim;
  const cv::Rect seed = (seed_box & window) - window.tl();
  if (seed.area() == 0) {
    out.failure = "seed outside the searched region";
    return out;
  }
  const cv::Mat bgr_window = bgr(window);
  cv::Mat raw, cls;
  ClassMasks(bgr_window, table, ball_bit, &raw, &cls);
  LabWindow lab(bgr_window);
  cv::Rect extent;
  const GrowClass grow{grow_table,
                       grow_table == nullptr || grow_bit != 0 ? grow_bit : grow_table->BallBit(),
                       grow_table == &table ? &cls : nullptr};
  const cv::Mat region = GrowAndCloseRegion(bgr_window, raw, grow, &lab, seed, o, &extent);
  if (region.empty()) {
    out.failure = "no ball-coloured pixels at the blob";
    return out;
  }
  std::vector<cv::Point> contour;
  cv::Mat filled;
  if (!LargestFilledOutline(region, extent, &contour, &filled)) {
    out.failure = "no outline";
    return out;
  }
  // The hull's vertices as indices into the contour; the points are those cv::convexHull gives.
  std::vector<int> hull_index;
  cv::convexHull(contour, hull_index, false, false);
  std::vector<cv::Point> hull;
  hull.reserve(hull_index.size());
  for (const int i : hull_index) hull.push_back(contour[i]);
  const double hull_area = cv::contourArea(hull) + 0.5 * cv::arcLength(hull, true) + 1.0;
  const double area = cv::countNonZero(filled(extent));
  out.area_px = area;
  out.solidity = std::min(1.0, area / hull_area);
  const double r_est = std::sqrt(hull_area / M_PI);
  const std::vector<Vector2d> pts = ConvexOutlinePoints(contour, hull_index, hull, window.tl(), lim,
                                                        o.hull_tolerance_px + 0.03 * r_est);
  out.outline_points = static_cast<int>(pts.size());
  if (pts.size() < 5) {
    out.failure = "too few convex outline points";
    return out;
  }
  Vector2d c;
  double r = 0;
  std::vector<char> inl;
  const double thr = o.inlier_px + 0.06 * r_est;
  if (!OuterCircle(pts, thr, o.inside_share * thr, 96, &c, &r, &inl) || !(r > 0.5) ||
      r > 2.5 * r_est + 3) {
    out.failure = "no circle in the outline";
    return out;
  }
  // Contour points are the centres of the region's border pixels: the edge lies half a pixel out.
  r += 0.5;
  const int bins = std::clamp(static_cast<int>(std::lround(M_PI * r)), 8, 36);
  const OutlineOnCircle on = MeasureOutlineOnCircle(pts, inl, c, r, thr, bins);
  int known = 0, hit = 0;
  CountSeenBins(bgr, c, r, on.bin_hit, lim, o.hidden_value, &known, &hit, &out.seen_rise);
  out.seen = double(known) / bins;
  out.partly_seen = out.seen < o.well_seen;
  out.failure = SeenProblem(out, c, lim, o);
  if (!out.failure.empty()) return out;
  out.inliers = on.inliers;
  out.outside = double(on.outside) / pts.size();
  // Corners are measured against the circle of the same band both ways: the outer outline's
  // circle passes near a polygon's corners (with inside_share 1 the two are one circle).
  Vector2d c_both = c;
  double r_both = r - 0.5;
  std::vector<char> inl_both;
  out.extent =
      o.inside_share < 1.0 && FitCircle(pts, thr, &c_both, &r_both, &inl_both) && r_both > 0.5
          ? OutlineExtent(pts, c_both, r_both + 0.5)
          : OutlineExtent(pts, c, r);
  out.rms_px = on.inliers > 0 ? std::sqrt(on.sum_sq / on.inliers) : 0.0;
  out.arc_cover = double(hit) / known;
  out.centre_px = c;
  out.radius_px = r;
  out.sigma_px = std::max(out.rms_px, 0.3) * std::sqrt(2.0 / std::max(on.inliers, 1)) + 0.05;
  // The field's surface: its colour and its painted lines.
  const uint8_t grass_bit = table.ClassBitOrZero("field");
  const uint8_t line_bit = table.ClassBitOrZero("line");
  const uint8_t field_bit = grass_bit | line_bit;
  // The colours are read within the leak ring's outer radius.
  const double ro = o.ring_outer * r;
  const cv::Point ring_tl(static_cast<int>(std::floor(c.x() - ro)) - 1,
                          static_cast<int>(std::floor(c.y() - ro)) - 1);
  const cv::Point ring_br(static_cast<int>(std::ceil(c.x() + ro)) + 2,
                          static_cast<int>(std::ceil(c.y() + ro)) + 2);
  const cv::Rect ring_box = cv::Rect(ring_tl, ring_br) - window.tl();
  {
    // Lab is read only within ro of the centre (the ring and the core): on each row of the box,
    // that chord, 1.5 px wider on both sides for rounding.
    const cv::Rect box = ring_box & cv::Rect(0, 0, window.width, window.height);
    std::vector<std::pair<int, int>> chords(box.height, {0, 0});
    for (int y = 0; y < box.height; ++y) {
      const double dy = window.y + box.y + y - c.y();
      if (std::abs(dy) > ro + 1) continue;
      const double half = std::sqrt(std::max(ro * ro - dy * dy, 0.0)) + 1.5;
      const double cx = c.x() - window.x - box.x;
      chords[y] = {std::clamp(static_cast<int>(std::floor(cx - half)), 0, box.width),
                   std::clamp(static_cast<int>(std::ceil(cx + half)) + 1, 0, box.width)};
    }
    lab.NeedSpans(box, chords);
  }
  const cv::Rect read = (ring_box | (cv::boundingRect(filled(extent)) + extent.tl())) &
                        cv::Rect(0, 0, window.width, window.height);
  MeasureRegionColours(bgr, window, lab.lab(), filled, raw, cls, read, c, r, area, o, field_bit,
                       grass_bit, &out);
  out.ok = true;
  return out;
}

}  // namespace fv::detect
