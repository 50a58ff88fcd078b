// The pretrained NanoDet-m (RangiLyu 2020, Apache-2.0; the 80 COCO classes), an ONNX model
// converted at set-up by scripts/nanodet_to_onnx.py and run with OpenCV's dnn: where the model
// lives, loading and checking it, NanoDet's input normalisation and the decoding of its GFL head
// (Li et al. 2020: per-stride class scores and 4 x 11-bin distance distributions at strides
// 8/16/32, box = centre -/+ stride * E[bin]) for any set of classes. Shared by the person detector
// (track/detection.h, class 0) and the ball detector's DNN path (detect/dnn_ball.h, class 32).
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

namespace fv::dnn {

inline constexpr int kCocoPerson = 0;
inline constexpr int kCocoSportsBall = 32;
inline constexpr int kCocoClasses = 80;

struct DnnBox {
  cv::Rect2d box;  // pixels (network or image, as the function says)
  double score = 0.0;
  int class_id = 0;  // COCO class index (0 person, 32 sports ball)
};

// Where the set-up put the models: $FV_MODELS_DIR, <program dir>/../models (as built),
// <program dir>/../share/fieldvision/models (as installed), ./models,
// ./build/models. Returns the first existing path of `file`, or throws fv::Error saying to run
// `make build` (which runs scripts/fetch-models.sh).
std::string FindModel(const std::string& file);

// An ONNX model on OpenCV's CPU backend. Throws fv::Error naming the path when it is missing or
// not a model OpenCV can read (`shipped`: the project's own model, which `make build` fetches
// again; the message says so).
cv::dnn::Net LoadOnnx(const std::string& path, bool shipped = false);

// NanoDet's decoder: the six outputs (cls8, cls16, cls32: 1 x N x 80; dis8, dis16, dis32:
// 1 x N x 44) of a net_width x net_height input -> boxes of `classes` in network pixels with
// score >= score_threshold (before NMS). Throws fv::Error when the sizes do not match the input
// or a class is not in 0..79.
std::vector<DnnBox> DecodeNanoDet(const std::vector<cv::Mat>& outputs, int net_width,
                                  int net_height, double score_threshold,
                                  const std::vector<int>& classes);

// Greedy NMS per class (cv::dnn::NMSBoxes), sorted by decreasing score.
std::vector<DnnBox> NmsBoxes(const std::vector<DnnBox>& boxes, double iou_threshold);

// The network, loaded once; not thread-safe (one per thread).
class NanoDet {
 public:
  // model_path "" = FindModel("nanodet.onnx"). Throws fv::Error for a missing or corrupt model,
  // or one without NanoDet's outputs (checked with a forward pass), saying how to get it.
  explicit NanoDet(const std::string& model_path = "");
  // Boxes of `classes` in a BGR image resized to net_size (multiples of 32), in the image's
  // pixels, score >= score_threshold, before NMS.
  std::vector<DnnBox> Detect(const cv::Mat& bgr, cv::Size net_size, double score_threshold,
                             const std::vector<int>& classes);
  const std::string& path() const { return path_; }

 private:
  std::vector<cv::Mat> Run(const cv::Mat& resized);
  std::string path_;
  cv::dnn::Net net_;
};

}  // namespace fv::dnn
