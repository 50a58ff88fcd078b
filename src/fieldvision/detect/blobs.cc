#include "fieldvision/detect/blobs.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "fieldvision/detect/search_area.h"
#include "fieldvision/util/error.h"

namespace fv::detect {
namespace {

int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

void Union(std::vector<int>& parent, int a, int b) {
  a = Find(parent, a);
  b = Find(parent, b);
  if (a != b) parent[std::max(a, b)] = std::min(a, b);
}

// Classifies samples x = x_start, x_start + step, ... of one row into `cls` (kStep > 0: the step
// known at compile time).
template <int kStep>
void ClassifyRow(const uint8_t* row, int n, int x_start, int step, const ColourTable& table,
                 uint8_t* cls) {
  table.ClassifyRow<kStep>(row + 3 * static_cast<ptrdiff_t>(x_start), n, step, cls);
}

}  // namespace

void ScanOptions::Check() const {
  FV_REQUIRE(step_px >= 1 && step_px <= 16, "scan step_px must be 1..16 (got {})", step_px);
  FV_REQUIRE(min_samples >= 1, "scan min_samples must be >= 1 (got {})", min_samples);
}

double Blob::aspect_ratio() const {
  const double w = width_px(), h = height_px();
  return std::max(w, h) / std::min(w, h);
}

double Blob::equivalent_radius_px() const { return std::sqrt(area_px() / M_PI); }

std::string BlobScanResult::Summary() const {
  return fmt::format("{} samples, {} runs, {} blobs", samples, runs, blobs.size());
}

namespace {

// Run-length encoding of one scanned row's classes `cls` (n samples at xs + i * step): runs of
// `class_mask` appended to `runs`, each its own set in `parent`. Skips 8 samples at a time while
// none has the class.
void AppendRowRuns(const std::vector<uint8_t>& cls, int n, int xs, int step, int y,
                   uint8_t class_mask, std::vector<Run>* runs, std::vector<int>* parent) {
  uint64_t mask8;
  std::memset(&mask8, class_mask, sizeof(mask8));
  int i = 0;
  while (i < n) {
    uint64_t word;
    std::memcpy(&word, cls.data() + i, 8);
    if ((word & mask8) == 0) {
      i += 8;
      continue;
    }
    if (!(cls[i] & class_mask)) {
      ++i;
      continue;
    }
    int j = i + 1;
    while (j < n && (cls[j] & class_mask)) ++j;
    runs->push_back({y, xs + i * step, xs + (j - 1) * step});
    parent->push_back(static_cast<int>(parent->size()));
    i = j;
  }
}

// Joins the runs [cur_begin, cur_end) of a row with those [prev_begin, prev_end) of the row
// scanned before it (both sorted by x): 8-connected on the sample grid.
void MergeWithPreviousRow(const std::vector<Run>& runs, int prev_begin, int prev_end, int cur_begin,
                          int cur_end, int step, std::vector<int>* parent) {
  if (prev_end <= prev_begin || cur_end <= cur_begin) return;
  if (runs[prev_begin].y != runs[cur_begin].y - step) return;
  int a = prev_begin, b = cur_begin;
  while (a < prev_end && b < cur_end) {
    const Run& p = runs[a];
    const Run& c = runs[b];
    if (p.x0 <= c.x1 + step && c.x0 <= p.x1 + step) Union(*parent, a, b);
    if (p.x1 < c.x1) {
      ++a;
    } else {
      ++b;
    }
  }
}

// One blob per set of runs, with its bounds, sample count and moments; blobs under
// `min_samples` left out, the largest first.
std::vector<Blob> BlobsFromRuns(const std::vector<Run>& runs, std::vector<int>& parent, int step,
                                int min_samples) {
  std::vector<Blob> blobs;
  std::vector<int> blob_of(runs.size(), -1);
  for (size_t r = 0; r < runs.size(); ++r) {
    const int root = Find(parent, static_cast<int>(r));
    if (blob_of[root] < 0) {
      blob_of[root] = static_cast<int>(blobs.size());
      Blob b;
      b.x_min = runs[r].x0;
      b.x_max = runs[r].x1;
      b.y_min = b.y_max = runs[r].y;
      b.step_px = step;
      blobs.push_back(b);
    }
    Blob& b = blobs[blob_of[root]];
    const Run& run = runs[r];
    const int samples = (run.x1 - run.x0) / step + 1;
    const double cnt = samples;
    const double k1 = cnt * (cnt - 1) / 2, k2 = (cnt - 1) * cnt * (2 * cnt - 1) / 6;
    const double sx = cnt * run.x0 + step * k1;
    const double sxx = cnt * double(run.x0) * run.x0 + 2.0 * run.x0 * step * k1 + step * step * k2;
    b.x_min = std::min(b.x_min, run.x0);
    b.x_max = std::max(b.x_max, run.x1);
    b.y_min = std::min(b.y_min, run.y);
    b.y_max = std::max(b.y_max, run.y);
    b.samples += static_cast<int>(cnt);
    b.runs += 1;
    b.sum_x += sx;
    b.sum_xx += sxx;
    b.sum_y += cnt * run.y;
    b.sum_yy += cnt * double(run.y) * run.y;
    b.sum_xy += sx * run.y;
  }
  blobs.erase(std::remove_if(blobs.begin(), blobs.end(),
                             [&](const Blob& b) { return b.samples < min_samples; }),
              blobs.end());
  std::sort(blobs.begin(), blobs.end(),
            [](const Blob& a, const Blob& b) { return a.samples > b.samples; });
  return blobs;
}

}  // namespace

BlobScanResult ScanBlobs(const cv::Mat& bgr, const ColourTable& table, uint8_t class_mask,
                         const ScanOptions& options, const cv::Mat& mask, const cv::Rect& region) {
  options.Check();
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "ScanBlobs: expected a BGR 8-bit image");
  FV_REQUIRE(mask.empty() || (mask.type() == CV_8U && mask.size() == bgr.size()),
             "ScanBlobs: mask must be CV_8U of the image size");
  const cv::Rect roi = SearchArea(bgr.size(), region);
  const int step = options.step_px;
  const int offset = step / 2;
  // The sample grid is that of the whole image (offset + k * step), so a region finds exactly
  // what the whole-image scan finds there.
  auto first_at_or_after = [&](int v) { return v <= offset ? 0 : (v - offset + step - 1) / step; };
  const int i0 = first_at_or_after(roi.x);
  const int i_end = first_at_or_after(roi.x + roi.width);
  const int n = std::max(0, i_end - i0);
  const int xs = offset + i0 * step;
  const int y0 = offset + first_at_or_after(roi.y) * step;
  const int y_end = roi.y + roi.height;
  BlobScanResult result;
  std::vector<uint8_t> cls(n + 8, 0);
  std::vector<Run> runs;
  runs.reserve(1024);
  std::vector<int> parent;
  parent.reserve(1024);
  int prev_begin = 0, prev_end = 0;
  for (int y = y0; y < y_end; y += step) {
    const uint8_t* row = bgr.ptr<uint8_t>(y);
    switch (step) {
      case 2:
        ClassifyRow<2>(row, n, xs, step, table, cls.data());
        break;
      case 4:
        ClassifyRow<4>(row, n, xs, step, table, cls.data());
        break;
      default:
        ClassifyRow<0>(row, n, xs, step, table, cls.data());
    }
    if (!mask.empty()) {
      const uint8_t* m = mask.ptr<uint8_t>(y);
      for (int i = 0; i < n; ++i) cls[i] &= m[xs + i * step] ? 0xFF : 0;
    }
    result.samples += n;
    const int cur_begin = static_cast<int>(runs.size());
    AppendRowRuns(cls, n, xs, step, y, class_mask, &runs, &parent);
    const int cur_end = static_cast<int>(runs.size());
    MergeWithPreviousRow(runs, prev_begin, prev_end, cur_begin, cur_end, step, &parent);
    prev_begin = cur_begin;
    prev_end = cur_end;
  }
  result.runs = static_cast<int>(runs.size());
  result.blobs = BlobsFromRuns(runs, parent, step, options.min_samples);
  return result;
}

}  // namespace fv::detect
