#include "fieldvision/dnn/nanodet.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>

#include <spdlog/spdlog.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/program_paths.h"

namespace fv::dnn {
namespace fs = std::filesystem;

std::string FindModel(const std::string& file) {
  std::vector<fs::path> dirs;
  if (const char* env = std::getenv("FV_MODELS_DIR")) dirs.emplace_back(env);
  std::error_code ec;
  const fs::path bin = util::ProgramDir();
  if (!bin.empty()) {
    dirs.push_back(bin.parent_path() / "models");
    dirs.push_back(util::InstalledDataDir() / "models");
  }
  dirs.push_back(fs::current_path(ec) / "models");
  dirs.push_back(fs::current_path(ec) / "build" / "models");
  std::string looked;
  for (const auto& d : dirs) {
    const fs::path p = d / file;
    if (fs::exists(p, ec)) {
      spdlog::debug("model: {}", p.string());
      return p.string();
    }
    looked += (looked.empty() ? "" : ", ") + d.string();
  }
  Throw(
      "model '{}' not found (looked in {}); run `make build`, which fetches and converts it "
      "(scripts/fetch-models.sh BUILD_DIR)",
      file, looked);
}

cv::dnn::Net LoadOnnx(const std::string& path, bool shipped) {
  // `make build` fetches and converts the shipped model; a user's own model is theirs to mend.
  const std::string again = shipped ? "; run `make build` to fetch and convert it again" : "";
  FV_REQUIRE(fs::exists(path), "model '{}' not found{}", path, again);
  cv::dnn::Net net;
  try {
    net = cv::dnn::readNetFromONNX(path);
  } catch (const cv::Exception& e) {
    Throw("model '{}' is corrupt or not an ONNX model OpenCV can read{}", path, again);
  }
  FV_REQUIRE(!net.empty(), "model '{}' has no layers{}", path, again);
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  return net;
}

std::vector<DnnBox> DecodeNanoDet(const std::vector<cv::Mat>& outputs, int net_width,
                                  int net_height, double score_threshold,
                                  const std::vector<int>& classes) {
  FV_REQUIRE(outputs.size() == 6, "NanoDet: expected 6 outputs, got {}", outputs.size());
  for (int c : classes) {
    FV_REQUIRE(c >= 0 && c < kCocoClasses, "NanoDet: class {} is not in 0..79", c);
  }
  constexpr int kStrides[3] = {8, 16, 32};
  constexpr int kBins = 11;
  std::vector<DnnBox> dets;
  for (int level = 0; level < 3; ++level) {
    const int s = kStrides[level];
    const int fw = (net_width + s - 1) / s, fh = (net_height + s - 1) / s;
    const cv::Mat& cls = outputs[level];
    const cv::Mat& dis = outputs[3 + level];
    FV_REQUIRE(cls.total() == size_t(fw) * fh * kCocoClasses && dis.total() == size_t(fw) * fh * 44,
               "NanoDet: output sizes do not match a {}x{} input", net_width, net_height);
    const float* c = cls.ptr<float>();
    const float* d = dis.ptr<float>();
    for (int idx = 0; idx < fw * fh; ++idx) {
      for (int class_id : classes) {
        const float score = c[idx * kCocoClasses + class_id];
        if (score < score_threshold) continue;
        const int col = idx % fw, row = idx / fw;  // the cell of this anchor
        const double cx = (col + 0.5) * s, cy = (row + 0.5) * s;
        double side[4];
        for (int k = 0; k < 4; ++k) {
          const float* bins = d + static_cast<ptrdiff_t>(idx * 44 + k * kBins);
          const float mx = *std::max_element(bins, bins + kBins);
          double sum = 0, mean = 0;
          for (int b = 0; b < kBins; ++b) {
            const double e = std::exp(double(bins[b]) - mx);
            sum += e;
            mean += e * b;
          }
          side[k] = mean / sum * s;
        }
        const double x0 = std::max(0.0, cx - side[0]), y0 = std::max(0.0, cy - side[1]);
        const double x1 = std::min<double>(net_width, cx + side[2]);
        const double y1 = std::min<double>(net_height, cy + side[3]);
        if (x1 <= x0 || y1 <= y0) continue;
        dets.push_back({cv::Rect2d(x0, y0, x1 - x0, y1 - y0), score, class_id});
      }
    }
  }
  return dets;
}

std::vector<DnnBox> NmsBoxes(const std::vector<DnnBox>& boxes, double iou_threshold) {
  std::map<int, std::vector<int>> by_class;
  for (size_t i = 0; i < boxes.size(); ++i) by_class[boxes[i].class_id].push_back(int(i));
  std::vector<DnnBox> out;
  for (const auto& [class_id, idx] : by_class) {
    std::vector<cv::Rect2d> rects;
    std::vector<float> scores;
    for (int i : idx) {
      rects.push_back(boxes[i].box);
      scores.push_back(static_cast<float>(boxes[i].score));
    }
    std::vector<int> keep;
    cv::dnn::NMSBoxes(rects, scores, 0.0f, static_cast<float>(iou_threshold), keep);
    for (int k : keep) out.push_back(boxes[idx[k]]);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const DnnBox& a, const DnnBox& b) { return a.score > b.score; });
  return out;
}

NanoDet::NanoDet(const std::string& model_path)
    : path_(model_path.empty() ? FindModel("nanodet.onnx") : model_path),
      net_(LoadOnnx(path_, model_path.empty())) {
  // A forward pass on a blank image checks that the model has NanoDet's outputs.
  try {
    Run(cv::Mat(128, 128, CV_8UC3, cv::Scalar::all(0)));
  } catch (const cv::Exception& e) {
    Throw("model '{}' does not run as NanoDet (outputs cls8..dis32 expected){}", path_,
          model_path.empty() ? "; run `make build` to convert it again" : "");
  }
}

std::vector<cv::Mat> NanoDet::Run(const cv::Mat& resized) {
  cv::Mat f;
  resized.convertTo(f, CV_32FC3);
  cv::subtract(f, cv::Scalar(103.53, 116.28, 123.675), f);
  cv::multiply(f, cv::Scalar(1 / 57.375, 1 / 57.12, 1 / 58.395), f);
  net_.setInput(cv::dnn::blobFromImage(f));
  std::vector<cv::Mat> outs;
  net_.forward(outs, std::vector<cv::String>{"cls8", "cls16", "cls32", "dis8", "dis16", "dis32"});
  return outs;
}

std::vector<DnnBox> NanoDet::Detect(const cv::Mat& bgr, cv::Size net_size, double score_threshold,
                                    const std::vector<int>& classes) {
  FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "nanodet: expected a BGR image");
  FV_REQUIRE(net_size.width >= 32 && net_size.height >= 32 && net_size.width % 32 == 0 &&
                 net_size.height % 32 == 0,
             "nanodet: network size {}x{} is not a multiple of 32", net_size.width,
             net_size.height);
  cv::Mat resized;
  if (bgr.size() == net_size) {
    resized = bgr;
  } else {
    cv::resize(bgr, resized, net_size, 0, 0, cv::INTER_LINEAR);
  }
  std::vector<DnnBox> dets =
      DecodeNanoDet(Run(resized), net_size.width, net_size.height, score_threshold, classes);
  const double sx = double(bgr.cols) / net_size.width, sy = double(bgr.rows) / net_size.height;
  for (auto& d : dets) {
    d.box = cv::Rect2d(d.box.x * sx, d.box.y * sy, d.box.width * sx, d.box.height * sy);
  }
  return dets;
}

}  // namespace fv::dnn
