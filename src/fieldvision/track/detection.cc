#include "fieldvision/track/detection.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>
#include <opencv2/video/background_segm.hpp>

#include "fieldvision/geometry/rigid.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::track {

void DetectorOptions::Check() const {
  FV_REQUIRE(kind == "nanodet" || kind == "hog" || kind == "motion" || kind == "onnx",
             "detector kind '{}' is not one of nanodet, hog, motion, onnx", kind);
  FV_REQUIRE(
      input_width == 0 || (input_width >= 64 && input_width <= 4096 && input_width % 32 == 0),
      "input_width must be 0 (from the frame) or a multiple of 32 in 64..4096 (got {})",
      input_width);
  FV_REQUIRE(
      input_height == 0 || (input_height >= 64 && input_height <= 4096 && input_height % 32 == 0),
      "input_height must be 0 or a multiple of 32 in 64..4096 (got {})", input_height);
  CheckInRange(score_threshold, 0.0, 1.0, "score_threshold");
  CheckInRange(nms_iou, 0.0, 1.0, "nms_iou");
  CheckNonNegative(min_height_px, "min_height_px");
  CheckNonNegative(threads, "threads");
  CheckInRange(hog_upscale, 0.25, 4.0, "hog_upscale");
  CheckFinite(hog_hit_threshold, "hog_hit_threshold");
  CheckFinite(hog_margin_at_half, "hog_margin_at_half");
  CheckPositive(motion_history, "motion_history");
  CheckPositive(motion_var_threshold, "motion_var_threshold");
  CheckInRange(motion_min_fill, 0.0, 1.0, "motion_min_fill");
  CheckPositive(person_height_m, "person_height_m");
  CheckPositive(person_width_m, "person_width_m");
  CheckNonNegative(onnx_person_class, "onnx_person_class");
  FV_REQUIRE(kind != "onnx" || !model_path.empty(),
             "detector 'onnx' needs a model file (--onnx MODEL.onnx)");
}

int NetInputWidth(int input_width, int frame_width) {
  if (input_width > 0) return input_width;
  const int half = static_cast<int>(std::lround(0.5 * frame_width / 32.0)) * 32;
  return std::clamp(half, 416, 960);
}

double Iou(const cv::Rect2d& a, const cv::Rect2d& b) {
  const double inter = (a & b).area();
  const double uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

std::vector<Detection> Nms(const std::vector<Detection>& detections, double iou_threshold,
                           double score_threshold) {
  std::vector<cv::Rect2d> boxes;
  std::vector<float> scores;
  for (const auto& d : detections) {
    boxes.push_back(d.box);
    scores.push_back(static_cast<float>(d.score));
  }
  std::vector<int> keep;
  cv::dnn::NMSBoxes(boxes, scores, static_cast<float>(score_threshold),
                    static_cast<float>(iou_threshold), keep);
  std::vector<Detection> out;
  out.reserve(keep.size());
  for (int i : keep) out.push_back(detections[i]);
  std::sort(out.begin(), out.end(),
            [](const Detection& a, const Detection& b) { return a.score > b.score; });
  return out;
}

std::vector<Detection> FilterDetections(std::vector<Detection> dets, const DetectorOptions& o,
                                        const FootFilter& filter) {
  std::erase_if(dets, [&](const Detection& d) { return d.box.height < o.min_height_px; });
  if (filter) {
    std::erase_if(dets, [&](const Detection& d) {
      return !filter({d.box.x + 0.5 * d.box.width, d.box.y + d.box.height});
    });
  }
  return Nms(dets, o.nms_iou, o.score_threshold);
}

void WriteDetectionsCsv(const DetectionsFile& detections, const std::string& path) {
  std::string out;
  for (size_t f = 0; f < detections.frames.size(); ++f) {
    for (const Detection& d : detections.frames[f]) {
      // {} is the shortest text that reads back as the same double.
      out += fmt::format("{},-1,{},{},{},{},{}\n", f + 1, d.box.x, d.box.y, d.box.width,
                         d.box.height, d.score);
    }
  }
  util::WriteTextFile(path, out, "detections file");
}

const std::vector<std::string>& MotColumns() {
  static const std::vector<std::string> kColumns = {
      "frame",     "id",   "bb_left",   "bb_top",         "bb_width",
      "bb_height", "conf", "mot_class", "mot_visibility", "mot_9"};
  return kColumns;
}

DetectionsFile ReadDetectionsCsv(const std::string& path) {
  const util::CsvTable t = util::CsvTable::ParseHeaderless(
      util::ReadCsvText(path, "detections file"), "detections file " + path, MotColumns());
  FV_REQUIRE(t.rows() == 0 || t.header().size() >= 7,
             "{}: expected at least 7 columns (frame,-1,bb_left,bb_top,bb_width,bb_height,"
             "score), got {}",
             t.Where(0), t.header().size());
  DetectionsFile out;
  for (size_t i = 0; i < t.rows(); ++i) {
    const std::string where = t.Where(i);
    const long long frame = t.GetInt(i, "frame");
    FV_REQUIRE(frame >= 1 && frame <= 10000000,
               "{}: frame {} is not in 1..10000000 (frames count "
               "from 1)",
               where, frame);
    Detection d;
    d.box = cv::Rect2d(t.GetDouble(i, "bb_left"), t.GetDouble(i, "bb_top"),
                       t.GetDouble(i, "bb_width"), t.GetDouble(i, "bb_height"));
    FV_REQUIRE(std::isfinite(d.box.x) && std::isfinite(d.box.y) && d.box.width >= 0 &&
                   d.box.height >= 0 && std::isfinite(d.box.width) && std::isfinite(d.box.height),
               "{}: box must be finite with a non-negative size", where);
    d.score = t.GetDouble(i, "conf");
    FV_REQUIRE(std::isfinite(d.score), "{}: score is not finite", where);
    if (out.frames.size() < size_t(frame)) out.frames.resize(frame);
    out.frames[frame - 1].push_back(d);
  }
  return out;
}

namespace {

using fv::dnn::LoadOnnx;

std::vector<Detection> Finish(std::vector<Detection> dets, const DetectorOptions& o,
                              const FootFilter& filter) {
  return FilterDetections(std::move(dets), o, filter);
}

class NanoDetDetector : public PersonDetector {
 public:
  NanoDetDetector(const DetectorOptions& o, FootFilter filter)
      : o_(o), filter_(std::move(filter)), net_(o.model_path) {}
  std::string name() const override { return "nanodet"; }

  std::vector<Detection> Detect(const cv::Mat& bgr) override {
    FV_REQUIRE(!bgr.empty() && bgr.type() == CV_8UC3, "nanodet: expected a BGR frame");
    const int net_w = NetInputWidth(o_.input_width, bgr.cols);
    const int net_h =
        o_.input_height > 0
            ? o_.input_height
            : std::max(
                  32,
                  static_cast<int>(std::lround(net_w * double(bgr.rows) / bgr.cols / 32.0)) * 32);
    std::vector<Detection> dets;
    for (const dnn::DnnBox& b :
         net_.Detect(bgr, cv::Size(net_w, net_h), o_.score_threshold, {dnn::kCocoPerson})) {
      dets.push_back({b.box, b.score});
    }
    return Finish(std::move(dets), o_, filter_);
  }

 private:
  DetectorOptions o_;
  FootFilter filter_;
  dnn::NanoDet net_;
};

class HogDetector : public PersonDetector {
 public:
  HogDetector(const DetectorOptions& o, FootFilter filter) : o_(o), filter_(std::move(filter)) {
    hog_.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
  }
  std::string name() const override { return "hog"; }
  std::vector<Detection> Detect(const cv::Mat& bgr) override {
    FV_REQUIRE(!bgr.empty(), "hog: empty frame");
    cv::Mat img;
    cv::resize(bgr, img, cv::Size(), o_.hog_upscale, o_.hog_upscale, cv::INTER_LINEAR);
    std::vector<cv::Rect> rects;
    std::vector<double> weights;
    hog_.detectMultiScale(img, rects, weights, o_.hog_hit_threshold, cv::Size(8, 8), cv::Size(),
                          1.05, 0.0, false);
    std::vector<Detection> dets;
    const double s = 1.0 / o_.hog_upscale;
    for (size_t i = 0; i < rects.size(); ++i) {
      // The 64 x 128 window holds a person of about 32 x 100 pixels: shrink to the person.
      const cv::Rect2d r(rects[i].x * s, rects[i].y * s, rects[i].width * s, rects[i].height * s);
      const cv::Rect2d person(r.x + 0.22 * r.width, r.y + 0.08 * r.height, 0.56 * r.width,
                              0.84 * r.height);
      dets.push_back({person, 1.0 / (1.0 + std::exp(-2.0 * (weights[i] - o_.hog_margin_at_half)))});
    }
    return Finish(std::move(dets), o_, filter_);
  }

 private:
  DetectorOptions o_;
  FootFilter filter_;
  cv::HOGDescriptor hog_;
};

class MotionDetector : public PersonDetector {
 public:
  MotionDetector(const DetectorOptions& o, const camera::Camera* camera, FootFilter filter)
      : o_(o), filter_(std::move(filter)) {
    if (camera != nullptr && camera->has_pose) camera_ = *camera;
    mog_ = cv::createBackgroundSubtractorMOG2(o.motion_history, o.motion_var_threshold, true);
  }
  std::string name() const override { return "motion"; }

  // Expected person box size (w, h) in pixels with the foot at `foot`; nullopt without a camera.
  std::optional<cv::Size2d> Expected(const cv::Point2d& foot) const {
    if (!camera_) return std::nullopt;
    const auto ray = camera_->RayFromPixel({foot.x, foot.y});
    if (!ray) return std::nullopt;
    const auto ground = geometry::IntersectHorizontalPlane(*ray, 0.0);
    if (!ground) return std::nullopt;
    const auto head = camera_->Project(*ground + Eigen::Vector3d(0, 0, o_.person_height_m));
    if (!head) return std::nullopt;
    const double h = std::abs(foot.y - head->y());
    return cv::Size2d(h * o_.person_width_m / o_.person_height_m, h);
  }

  std::vector<Detection> Detect(const cv::Mat& bgr) override {
    FV_REQUIRE(!bgr.empty(), "motion: empty frame");
    cv::Mat fg;
    mog_->apply(bgr, fg);
    cv::threshold(fg, fg, 200, 255, cv::THRESH_BINARY);  // drop shadows (127)
    cv::morphologyEx(fg, fg, cv::MORPH_OPEN,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3)));
    cv::morphologyEx(fg, fg, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 9)));
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(fg, labels, stats, centroids, 8, CV_32S);
    std::vector<Detection> dets;
    for (int i = 1; i < n; ++i) {
      const cv::Rect blob(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                          stats.at<int>(i, cv::CC_STAT_WIDTH),
                          stats.at<int>(i, cv::CC_STAT_HEIGHT));
      const double area = stats.at<int>(i, cv::CC_STAT_AREA);
      if (area < 30) continue;
      const cv::Point2d foot(blob.x + 0.5 * blob.width, blob.y + blob.height);
      const auto expected = Expected(foot);
      const double exp_w = expected ? expected->width : 0.4 * blob.height;
      const double exp_h = expected ? expected->height : blob.height;
      if (exp_h < 8) continue;
      if (blob.height < 0.4 * exp_h) continue;  // too short to be a person
      // Split blobs wider than one person into side-by-side people.
      const int parts = std::max(1, static_cast<int>(std::lround(blob.width / (1.2 * exp_w))));
      const double part_w = double(blob.width) / parts;
      for (int k = 0; k < parts; ++k) {
        const cv::Rect part(static_cast<int>(blob.x + k * part_w), blob.y,
                            std::max(1, static_cast<int>(part_w)), blob.height);
        cv::Mat mask = (labels(part) == i);
        const double fill = cv::countNonZero(mask);
        const double expected_area = exp_w * std::min<double>(exp_h, blob.height);
        if (fill < o_.motion_min_fill * expected_area) continue;
        // Tighten the part to its own pixels.
        const cv::Rect tight = cv::boundingRect(mask) + part.tl();
        const double score = std::clamp(fill / std::max(1.0, exp_w * exp_h), 0.0, 1.0);
        dets.push_back({cv::Rect2d(tight), 0.3 + 0.7 * score});
      }
    }
    return Finish(std::move(dets), o_, filter_);
  }

 private:
  DetectorOptions o_;
  FootFilter filter_;
  std::optional<camera::Camera> camera_;
  cv::Ptr<cv::BackgroundSubtractorMOG2> mog_;
};

// A YOLO-style model (YOLOv5/v8 exports): one output of rows (cx, cy, w, h, obj, classes...) or,
// for v8, (cx, cy, w, h, classes...) transposed; square input of input_width.
class OnnxYoloDetector : public PersonDetector {
 public:
  OnnxYoloDetector(const DetectorOptions& o, FootFilter filter)
      : o_(o), filter_(std::move(filter)), net_(LoadOnnx(o.model_path)) {}
  std::string name() const override { return "onnx"; }
  std::vector<Detection> Detect(const cv::Mat& bgr) override {
    const int s = o_.input_width > 0 ? o_.input_width : 640;  // YOLO models' usual size
    net_.setInput(cv::dnn::blobFromImage(bgr, 1.0 / 255, cv::Size(s, s), cv::Scalar(), true));
    cv::Mat out;
    try {
      out = net_.forward();
    } catch (const cv::Exception& e) {
      Throw("model '{}' failed to run on a {}x{} input: {}", o_.model_path, s, s,
            e.err.substr(0, 120));
    }
    FV_REQUIRE(out.dims == 3, "model '{}': expected a 1 x N x K output", o_.model_path);
    cv::Mat rows(out.size[1], out.size[2], CV_32F, out.ptr<float>());
    bool v8 = false;
    if (rows.rows < rows.cols) {  // 1 x (4 + C) x N (YOLOv8): transpose
      rows = rows.t();
      v8 = true;
    }
    const int first_class = v8 ? 4 : 5;
    FV_REQUIRE(rows.cols > first_class + o_.onnx_person_class,
               "model '{}': {} columns per row, too few for class {}", o_.model_path, rows.cols,
               o_.onnx_person_class);
    const double sx = double(bgr.cols) / s, sy = double(bgr.rows) / s;
    std::vector<Detection> dets;
    for (int r = 0; r < rows.rows; ++r) {
      const float* p = rows.ptr<float>(r);
      const double score = (v8 ? 1.0 : p[4]) * p[first_class + o_.onnx_person_class];
      if (score < o_.score_threshold) continue;
      dets.push_back(
          {cv::Rect2d((p[0] - 0.5 * p[2]) * sx, (p[1] - 0.5 * p[3]) * sy, p[2] * sx, p[3] * sy),
           score});
    }
    return Finish(std::move(dets), o_, filter_);
  }

 private:
  DetectorOptions o_;
  FootFilter filter_;
  cv::dnn::Net net_;
};

}  // namespace

std::vector<Detection> DecodeNanoDet(const std::vector<cv::Mat>& outputs, int net_width,
                                     int net_height, double score_threshold) {
  std::vector<Detection> dets;
  for (const dnn::DnnBox& b :
       dnn::DecodeNanoDet(outputs, net_width, net_height, score_threshold, {dnn::kCocoPerson})) {
    dets.push_back({b.box, b.score});
  }
  return dets;
}

std::unique_ptr<PersonDetector> MakeDetector(const DetectorOptions& options,
                                             const camera::Camera* camera, FootFilter filter) {
  options.Check();
  if (options.threads > 0) cv::setNumThreads(options.threads);
  if (options.kind == "nanodet") {
    return std::make_unique<NanoDetDetector>(options, std::move(filter));
  }
  if (options.kind == "hog") return std::make_unique<HogDetector>(options, std::move(filter));
  if (options.kind == "motion") {
    return std::make_unique<MotionDetector>(options, camera, std::move(filter));
  }
  return std::make_unique<OnnxYoloDetector>(options, std::move(filter));
}

}  // namespace fv::track
