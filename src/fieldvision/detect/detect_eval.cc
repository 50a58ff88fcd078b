#include "fieldvision/detect/detect_eval.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/camera/frame_size.h"
#include "fieldvision/detect/camera_background.h"
#include "fieldvision/detect/eval_drawing.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/strings.h"

namespace fv::detect {
namespace fs = std::filesystem;

namespace {

// Images of a folder and its subfolders, in path order.
std::vector<std::string> ImagesUnder(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file() && io::IsImageFile(e.path().string())) {
      files.push_back(e.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string ReplaceCommas(std::string s) {
  std::replace(s.begin(), s.end(), ',', ';');
  return s;
}

cv::Rect2d Grow(const cv::Rect2d& r, double grow) {
  return {r.x - grow * r.width, r.y - grow * r.height, r.width * (1 + 2 * grow),
          r.height * (1 + 2 * grow)};
}

bool Inside(const cv::Rect2d& r, double u, double v) {
  return u >= r.x && u <= r.x + r.width && v >= r.y && v <= r.y + r.height;
}

// The first box, grown by `grow`, that holds (u, v); null when none does.
const cv::Rect2d* BoxHolding(const std::vector<cv::Rect2d>& boxes, double grow, double u,
                             double v) {
  for (const auto& b : boxes) {
    if (Inside(Grow(b, grow), u, v)) return &b;
  }
  return nullptr;
}

// The camera whose rows of a truth_2d.csv label `video`: `wanted`, else the video's file name
// without extension, else its folder's name (cam1.avi, cam1/%05d.png).
std::string LabelCamera(const util::CsvTable& t, const std::string& video,
                        const std::string& wanted) {
  std::set<std::string> cams;
  for (size_t r = 0; r < t.rows(); ++r) cams.insert(t.Get(r, "cam"));
  const fs::path p(video);
  const std::vector<std::string> tries =
      wanted.empty()
          ? std::vector<std::string>{p.stem().string(), p.parent_path().filename().string()}
          : std::vector<std::string>{wanted};
  for (const std::string& cam : tries) {
    if (cams.count(cam) > 0) return cam;
  }
  const auto joined = [](const auto& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "'" : ", '") + n + "'";
    return s.empty() ? std::string("none") : s;
  };
  Throw("labels '{}' have no rows of camera {} (cameras: {}): name one with --label-cam", t.name(),
        joined(tries), joined(cams));
}

// CSV labels: image (file name, path or stem) or frame, and x,y,w,h in pixels, or the circles of
// a truth_2d.csv (frame,cam,u_px,v_px,radius_px[,visible_fraction]), one camera's rows.
std::vector<LabelledImage> ReadCsvLabels(const std::vector<LabelledImage>& items,
                                         const std::string& video, const LabelOptions& o) {
  const util::CsvTable t = util::CsvTable::Read(o.labels);
  const std::string& path = o.labels;
  const bool circles = t.Has("u_px");
  t.Require(circles ? std::vector<std::string>{"u_px", "v_px", "radius_px"}
                    : std::vector<std::string>{"x", "y", "w", "h"});
  FV_REQUIRE(t.Has("image") || t.Has("frame"), "{}: needs a column 'image' or 'frame'", path);
  const std::string cam = circles && t.Has("cam") ? LabelCamera(t, video, o.camera) : "";
  FV_REQUIRE(o.camera.empty() || !cam.empty(),
             "--label-cam {} names a camera of a truth_2d.csv, but '{}' has no column 'cam'",
             o.camera, path);
  std::map<std::string, std::vector<cv::Rect2d>> by_key;
  std::set<std::string> hidden;  // keys with a ball less visible than min_visible
  for (size_t r = 0; r < t.rows(); ++r) {
    if (!cam.empty() && t.Get(r, "cam") != cam) continue;
    const std::string key = t.Has("image") ? t.Get(r, "image") : t.Get(r, "frame");
    if (t.Has("visible_fraction")) {
      const double visible = t.GetDouble(r, "visible_fraction");
      FV_REQUIRE(visible >= 0 && visible <= 1, "{}: visible_fraction must be in [0, 1]",
                 t.Where(r));
      if (visible == 0) continue;  // outside the image or hidden: no ball to find there
      if (visible < o.min_visible) {
        hidden.insert(key);
        continue;
      }
    }
    cv::Rect2d box;
    if (circles) {
      const double u = t.GetDouble(r, "u_px"), v = t.GetDouble(r, "v_px");
      const double radius = t.GetDouble(r, "radius_px");
      box = cv::Rect2d(u - radius, v - radius, 2 * radius, 2 * radius);
    } else {
      box = cv::Rect2d(t.GetDouble(r, "x"), t.GetDouble(r, "y"), t.GetDouble(r, "w"),
                       t.GetDouble(r, "h"));
    }
    FV_REQUIRE(std::isfinite(box.x) && std::isfinite(box.y) && box.width > 0 && box.height > 0,
               "{}: a box needs finite x, y and positive w, h (a circle: u_px, v_px and a "
               "positive radius_px)",
               t.Where(r));
    by_key[key].push_back(box);
  }
  std::vector<LabelledImage> out = items;
  for (auto& item : out) {
    item.has_label_file = true;
    std::vector<std::string> keys;
    if (item.frame >= 0) {
      keys = {std::to_string(item.frame)};
    } else {
      const fs::path p(item.image);
      const std::string stem = p.stem().string();
      keys = {item.image, p.filename().string(), stem};
      // A numbered image (00012.png) is also that frame (12).
      if (!stem.empty() && stem.size() < 18 &&
          std::all_of(stem.begin(), stem.end(),
                      [](unsigned char ch) { return std::isdigit(ch); })) {
        keys.push_back(std::to_string(std::stoll(stem)));
      }
    }
    for (const auto& k : keys) {
      const auto it = by_key.find(k);
      if (it != by_key.end()) {
        item.boxes = it->second;
        break;
      }
    }
    item.judged = !item.boxes.empty() ||
                  std::none_of(keys.begin(), keys.end(),
                               [&](const std::string& k) { return hidden.count(k) > 0; });
  }
  // A video's labels past its last frame: the labels of another video (or cut), which would be
  // scored against frames they do not describe.
  const bool video_frames = !out.empty() && out.front().frame >= 0 && !t.Has("image");
  // A container without a frame index gives FFmpeg's estimate of the count: a little slack.
  const long long count = static_cast<long long>(out.size());
  for (auto it = by_key.begin(); video_frames && it != by_key.end(); ++it) {
    const std::string& key = it->first;
    long long frame = 0;
    const auto [end, ec] = std::from_chars(key.data(), key.data() + key.size(), frame);
    FV_REQUIRE(ec == std::errc() && end == key.data() + key.size(),
               "{}: frame '{}' is not a frame number", path, key);
    FV_REQUIRE(frame < count + std::max(2LL, count / 100),
               "{}: labels for frame {} but video '{}' has {} frames (labels of another video?)",
               path, frame, video, out.size());
  }
  return out;
}

}  // namespace

std::vector<cv::Rect2d> ReadYoloFile(const std::string& path, int class_id, int width, int height) {
  std::ifstream in(path);
  FV_REQUIRE(in.good(), "cannot read label file '{}'", path);
  util::SkipUtf8Bom(in);
  std::vector<cv::Rect2d> boxes;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream ss(line);
    double cls = 0, cx = 0, cy = 0, w = 0, h = 0;
    ss >> cls >> cx >> cy >> w >> h;
    std::string rest;
    const bool ok = !ss.fail() && !(ss >> rest) && cls == std::floor(cls) && cls >= 0 &&
                    std::isfinite(cx) && std::isfinite(cy) && w > 0 && h > 0 && w <= 1.5 &&
                    h <= 1.5;
    FV_REQUIRE(ok, "{}:{}: expected 'class cx cy w h' (YOLO, normalised to the image), got '{}'",
               path, line_no, line);
    // Normalised: a box must overlap the image [0, 1] x [0, 1] (pixels would be far outside).
    FV_REQUIRE(cx - 0.5 * w < 1 && cx + 0.5 * w > 0 && cy - 0.5 * h < 1 && cy + 0.5 * h > 0,
               "{}:{}: the box '{}' lies outside the image (YOLO boxes are normalised to 0..1)",
               path, line_no, line);
    if (static_cast<int>(cls) != class_id) continue;
    boxes.emplace_back((cx - 0.5 * w) * width, (cy - 0.5 * h) * height, w * width, h * height);
  }
  return boxes;
}

std::vector<LabelledImage> ReadYoloLabels(const std::vector<std::string>& images,
                                          const std::string& image_root, const std::string& labels,
                                          int class_id) {
  std::vector<LabelledImage> out;
  out.reserve(images.size());
  for (const auto& image : images) {
    LabelledImage item;
    item.image = image;
    const fs::path p(image);
    std::vector<fs::path> tries;
    if (labels.empty()) {
      tries.push_back(p.parent_path() / (p.stem().string() + ".txt"));
    } else {
      if (!image_root.empty()) {
        std::error_code ec;
        const fs::path rel = fs::relative(p, image_root, ec);
        if (!ec && !rel.empty() && *rel.begin() != "..") {
          tries.push_back(fs::path(labels) / rel.parent_path() / (rel.stem().string() + ".txt"));
        }
      }
      tries.push_back(fs::path(labels) / (p.stem().string() + ".txt"));
    }
    for (const auto& t : tries) {
      if (fs::is_regular_file(t)) {
        item.has_label_file = true;
        item.label_file = t.string();
        const cv::Mat im = io::ReadImage(image);  // the size normalises the boxes
        item.boxes = ReadYoloFile(t.string(), class_id, im.cols, im.rows);
        break;
      }
    }
    out.push_back(std::move(item));
  }
  return out;
}

void DetectEvalOptions::Check() const {
  FV_REQUIRE(!video.empty(), "eval detect: --video is required");
  FV_REQUIRE(labels.class_id >= 0, "--class must be >= 0 (got {})", labels.class_id);
  CheckInRange(labels.min_visible, 0.0, 1.0, "min_visible");
  CheckInRange(grow, 0.0, 5.0, "grow");
  FV_REQUIRE(list_misses >= 0, "list_misses must be >= 0");
  FV_REQUIRE(field.empty() || !camera.empty(),
             "eval detect: --field needs --camera with a pose (the field is found through it)");
  FV_REQUIRE(!transform || (camera.empty() && draw_misses.empty()),
             "eval detect: an image transform goes with neither a camera nor drawings");
  detector.Check();
  dnn.Check();
}

DetectEvalImage ScoreImage(const std::vector<BallCandidate>& candidates,
                           const std::vector<cv::Rect2d>& boxes, double grow) {
  DetectEvalImage r;
  r.boxes = static_cast<int>(boxes.size());
  const auto half_size = [](const cv::Rect2d& b) { return 0.5 * std::max(b.width, b.height); };
  for (const cv::Rect2d& b : boxes) r.ball_radius_px = std::max(r.ball_radius_px, half_size(b));
  auto box_of = [&](const BallCandidate& c) {
    return BoxHolding(boxes, grow, c.centre_px.x(), c.centre_px.y());
  };
  for (const auto& c : candidates) {
    if (box_of(c) == nullptr) continue;
    r.candidate_on_ball = true;
    if (c.accepted && !r.accepted_on_ball) r.reason = "an accepted one ranked below it";
    r.accepted_on_ball = r.accepted_on_ball || c.accepted;
    if (r.reason.empty() && !c.accepted) r.reason = c.reason;
  }
  // Candidates come best first; the first accepted one is the image's detection.
  const auto best = std::find_if(candidates.begin(), candidates.end(),
                                 [](const BallCandidate& c) { return c.accepted; });
  if (best == candidates.end()) {
    if (r.reason.empty()) r.reason = r.boxes > 0 ? "no candidate on the ball" : "";
    return r;
  }
  r.detected = true;
  r.u = best->centre_px.x();
  r.v = best->centre_px.y();
  r.radius_px = best->radius_px;
  r.score = best->score;
  const cv::Rect2d* box = box_of(*best);
  r.hit = box != nullptr;
  if (r.hit) {
    r.reason.clear();
    r.ball_radius_px = half_size(*box);
    const double cx = box->x + 0.5 * box->width, cy = box->y + 0.5 * box->height;
    r.centre_err_px = std::hypot(r.u - cx, r.v - cy);
    r.centre_err_rel = r.centre_err_px / (0.25 * (box->width + box->height));
  } else if (r.boxes > 0) {
    r.reason = fmt::format("best candidate off the ball at ({:.0f}, {:.0f})", r.u, r.v) +
               (r.reason.empty() ? "" : "; on the ball: " + r.reason);
  }
  return r;
}

namespace {

// A miss's reason without its numbers and where (what is in brackets, after "at" or ";"), so
// that misses of one kind count together.
std::string ReasonKind(const std::string& reason) {
  std::string kind = reason.substr(0, reason.find_first_of("(;"));
  for (const char* tail : {" at ", " "}) {
    if (kind.ends_with(tail)) kind.erase(kind.size() - std::strlen(tail));
  }
  std::string out;
  for (size_t i = 0; i < kind.size(); ++i) {
    const bool digit = std::isdigit(static_cast<unsigned char>(kind[i])) != 0;
    if (digit && (out.empty() || out.back() != 'N')) out += 'N';
    if (!digit && !(kind[i] == '.' && !out.empty() && out.back() == 'N')) out += kind[i];
  }
  return out;
}

// "count kind, ..." over the images with a ball that were missed, most frequent first.
std::string MissReasons(const std::vector<DetectEvalImage>& images) {
  std::map<std::string, int> counts;
  for (const auto& im : images) {
    if (im.boxes > 0 && !im.hit) ++counts[ReasonKind(im.reason)];
  }
  std::vector<std::pair<int, std::string>> sorted;
  sorted.reserve(counts.size());
  for (const auto& [kind, n] : counts) sorted.emplace_back(-n, kind);
  std::sort(sorted.begin(), sorted.end());
  std::string s;
  for (const auto& [n, kind] : sorted) s += fmt::format("{}{} {}", s.empty() ? "" : ", ", -n, kind);
  return s;
}

}  // namespace

std::string RecallBySize(const std::vector<DetectEvalImage>& images) {
  static constexpr std::array<double, 4> kEdges = {3.0, 6.0, 12.0, 24.0};
  std::array<int, kEdges.size() + 1> balls{}, hits{};
  for (const DetectEvalImage& im : images) {
    if (im.boxes == 0) continue;
    const auto bin =
        std::upper_bound(kEdges.begin(), kEdges.end(), im.ball_radius_px) - kEdges.begin();
    ++balls[bin];
    hits[bin] += im.hit;
  }
  std::string s;
  for (size_t i = 0; i < balls.size(); ++i) {
    if (balls[i] == 0) continue;
    const std::string range = i == 0 ? fmt::format("< {:g} px", kEdges[0])
                              : i == kEdges.size()
                                  ? fmt::format(">= {:g} px", kEdges.back())
                                  : fmt::format("{:g}-{:g} px", kEdges[i - 1], kEdges[i]);
    s += fmt::format("{}{} {:.3f} ({}/{})", s.empty() ? "" : ", ", range,
                     double(hits[i]) / balls[i], hits[i], balls[i]);
  }
  return s;
}

std::string DetectEvalResult::Summary(int list) const {
  std::vector<double> err_px, err_rel;
  for (const auto& im : images) {
    if (!im.hit) continue;
    err_px.push_back(im.centre_err_px);
    err_rel.push_back(im.centre_err_rel);
  }
  // A ratio of nothing is not a number: "n/a".
  const auto ratio = [](double v, int den) {
    return den > 0 ? fmt::format("{:.3f}", v) : std::string("n/a");
  };
  std::string s = fmt::format(
      "{} images, {} with a ball, {} with a detection: recall {} ({}/{}), precision {} ({}/{}), "
      "{} false detections",
      images.size(), with_ball, detected, ratio(recall(), with_ball), hits, with_ball,
      ratio(precision(), detected), hits, detected, false_detections);
  if (!camera_note.empty()) s += "\n" + camera_note;
  const std::string by_size = RecallBySize(images);
  if (!by_size.empty()) s += "\nrecall by ball radius (half the box's longer side): " + by_size;
  if (!err_px.empty()) {
    s += fmt::format(
        "\ncentre error vs. box centre: median {:.2f} px, p90 {:.2f} px ({:.2f} / {:.2f} of the "
        "box half size)",
        util::Median(err_px), util::Percentile(err_px, 0.9), util::Median(err_rel),
        util::Percentile(err_rel, 0.9));
  }
  int on_ball = 0, accepted_on_ball = 0;
  for (const auto& im : images) {
    on_ball += im.boxes > 0 && im.candidate_on_ball;
    accepted_on_ball += im.boxes > 0 && im.accepted_on_ball;
  }
  s += fmt::format(
      "\na candidate (accepted or not) lies on the ball in {}/{} images, an accepted one (first "
      "or not) in {}/{}",
      on_ball, with_ball, accepted_on_ball, with_ball);
  const std::string reasons = MissReasons(images);
  if (!reasons.empty()) s += "\nmisses by reason: " + reasons;
  if (not_judged > 0) {
    s += fmt::format("\n{} images whose ball is less visible than the labels' minimum not judged",
                     not_judged);
  }
  if (no_label_file > 0) {
    s += fmt::format("\n{} images have no label file (taken as images without a ball)",
                     no_label_file);
  }
  if (!background.empty()) s += "\n" + background;
  if (!drawn_dir.empty()) {
    s += fmt::format("\ndrew {} misses and false detections in {}", drawn, drawn_dir);
  }
  s += fmt::format("\n{:.1f} s ({:.1f} ms per image)", seconds,
                   images.empty() ? 0.0 : 1e3 * seconds / images.size());
  int listed = 0;
  for (const auto& im : images) {
    if (listed >= list) break;
    if (im.hit || (im.boxes == 0 && !im.detected)) continue;
    s += fmt::format("\n  {}: {}", im.image,
                     im.boxes == 0 ? fmt::format("false detection at ({:.0f}, {:.0f}) r {:.1f}",
                                                 im.u, im.v, im.radius_px)
                                   : "miss: " + im.reason);
    ++listed;
  }
  return s;
}

namespace {

// The next image: the video's next frame (false at its end) or the item's image file, checked
// against the camera's size (both named).
bool NextImage(io::VideoSource* video, const LabelledImage& item, const camera::Camera* camera,
               const std::string& camera_file, io::Frame* frame, cv::Mat* bgr) {
  if (video != nullptr) {
    if (!video->Read(*frame)) return false;
    *bgr = frame->bgr;
  } else {
    *bgr = io::ReadImage(item.image);
  }
  FV_REQUIRE(camera == nullptr || (bgr->cols == camera->width && bgr->rows == camera->height),
             "{} is {}x{} but camera file '{}' is {}x{}", item.image, bgr->cols, bgr->rows,
             camera_file, camera->width, camera->height);
  return true;
}

}  // namespace

std::vector<LabelledImage> ListLabelledImages(const std::string& video,
                                              const LabelOptions& label_options,
                                              const std::string& what) {
  const std::string& labels = label_options.labels;
  std::vector<LabelledImage> items;
  std::string root;
  const bool is_dir = fs::is_directory(video);
  std::vector<std::string> files = is_dir ? ImagesUnder(video) : io::ListImageSequence(video);
  bool is_video = false;
  if (is_dir) root = video;
  if (files.empty()) {
    FV_REQUIRE(!is_dir, "{}: folder '{}' holds no image", what, video);
    const std::unique_ptr<io::VideoSource> source =
        io::VideoSource::Open(video);  // throws naming the video
    is_video = true;
    FV_REQUIRE(!labels.empty() && fs::path(labels).extension() == ".csv",
               "{}: a video needs --labels LABELS.csv with columns frame,x,y,w,h (or synth's "
               "truth_2d.csv)",
               what);
    for (int i = 0; i < std::max(0, source->frame_count()); ++i) {
      LabelledImage item;
      item.image = fmt::format("{}#{}", video, i);
      item.frame = i;
      items.push_back(item);
    }
  } else {
    if (root.empty()) root = fs::path(files.front()).parent_path().string();
    for (const auto& f : files) {
      LabelledImage item;
      item.image = f;
      items.push_back(item);
    }
  }
  FV_REQUIRE(label_options.camera.empty() || fs::is_regular_file(labels),
             "{}: --label-cam names a camera of a truth_2d.csv file, not of YOLO labels", what);
  if (!labels.empty() && fs::is_regular_file(labels)) {
    items = ReadCsvLabels(items, video, label_options);
  } else if (!is_video) {
    FV_REQUIRE(labels.empty() || fs::is_directory(labels),
               "{}: labels '{}' is neither a folder of YOLO files nor a CSV file", what, labels);
    items = ReadYoloLabels(files, root, labels, label_options.class_id);
  } else {
    Throw("{}: labels '{}' not found", what, labels);
  }
  // Nothing to use without a single label file (a wrong --labels folder, a forgotten export).
  const bool any_label = std::any_of(items.begin(), items.end(),
                                     [](const LabelledImage& it) { return it.has_label_file; });
  FV_REQUIRE(any_label || items.empty(),
             "{}: none of the {} images has a label file (labels: '{}'): nothing to score", what,
             items.size(), labels.empty() ? "beside the images" : labels);
  return items;
}

namespace {

// --candidates: one row per candidate with its measurements, committed at the end.
void OpenCandidatesCsv(const std::string& path, std::unique_ptr<util::AtomicOutput>* file,
                       std::unique_ptr<util::CsvWriter>* csv) {
  *file = std::make_unique<util::AtomicOutput>(path, "--candidates");
  *csv = std::make_unique<util::CsvWriter>(
      (*file)->temp_path(),
      std::vector<std::string>{
          "image",        "u",       "v",           "radius_px", "score",     "accepted", "weak",
          "on_ball",      "visible", "inliers",     "outside",   "dents",     "region",   "arc",
          "fill",         "spill",   "leak",        "contrast",  "outside_r", "extent",   "precise",
          "hue_contrast", "network", "field_share", "rescued",   "apart",     "reason"},
      4);
}

// The image changed by `transform` and its boxes scaled as its size changed.
void TransformImage(const std::function<cv::Mat(const cv::Mat&)>& transform, cv::Mat* bgr,
                    std::vector<cv::Rect2d>* boxes) {
  cv::Mat changed = transform(*bgr);
  FV_REQUIRE(!changed.empty() && changed.type() == CV_8UC3,
             "eval detect: the image transform must give an 8-bit BGR image");
  const double sx = double(changed.cols) / bgr->cols, sy = double(changed.rows) / bgr->rows;
  for (cv::Rect2d& b : *boxes) b = cv::Rect2d(b.x * sx, b.y * sy, b.width * sx, b.height * sy);
  *bgr = std::move(changed);
}

}  // namespace

namespace {

// The camera file (null when none), fitted to a video's frames or to the first image before the
// detector takes it (an encoder's cropped padding: *note says so).
std::unique_ptr<camera::Camera> LoadEvalCamera(const std::string& path, io::VideoSource* video,
                                               const std::vector<LabelledImage>& items,
                                               std::string* note) {
  if (path.empty()) return nullptr;
  auto camera = std::make_unique<camera::Camera>(camera::ReadCameraYaml(path));
  if (video != nullptr) {
    *note = video->FitCamera(*camera, path);
  } else if (!items.empty()) {
    const cv::Mat first = io::ReadImage(items.front().image);
    *note = camera::FitCameraToFrames(*camera, fmt::format("camera file '{}'", path), first.cols,
                                      first.rows, fmt::format("image '{}'", items.front().image));
  }
  return camera;
}

}  // namespace

DetectEvalResult EvaluateDetector(const DetectEvalOptions& o) {
  o.Check();
  std::vector<LabelledImage> items = ListLabelledImages(o.video, o.labels, "eval detect");
  std::unique_ptr<io::VideoSource> video;
  if (!items.empty() && items.front().frame >= 0) video = io::VideoSource::Open(o.video);
  // No output may be one of the images, label files or the camera read (an image inside --video).
  std::vector<std::string> inputs = {o.video, o.labels.labels, o.camera, o.field};
  for (const LabelledImage& item : items) {
    inputs.push_back(item.image);
    inputs.push_back(item.label_file);
  }
  util::CheckOutputPath(o.out, inputs, "--out");
  util::CheckOutputPath(o.candidates_out, util::PathList(inputs, o.out), "--candidates");
  std::unique_ptr<MissDrawings> drawings;
  if (!o.draw_misses.empty()) {
    for (const auto& [path, what] :
         {std::pair{o.out, "--out"}, {o.candidates_out, "--candidates"}}) {
      FV_REQUIRE(path.empty() || !util::SameFile(path, o.draw_misses),
                 "{} '{}' is the --draw-misses folder", what, path);
    }
    std::vector<std::string> image_files;
    for (const LabelledImage& item : items) {
      if (item.frame < 0) image_files.push_back(item.image);
    }
    drawings = std::make_unique<MissDrawings>(o.draw_misses, o.video, image_files);
  }
  std::string camera_note;
  const std::unique_ptr<camera::Camera> camera =
      LoadEvalCamera(o.camera, video.get(), items, &camera_note);
  std::optional<field::FieldModel> field;
  if (!o.field.empty()) {
    FV_REQUIRE(camera->has_pose, "eval detect: --field needs a camera with a pose ('{}' has none)",
               o.camera);
    field = field::LoadField(o.field);
  }
  AnyBallDetector detector(o.detector, o.dnn, camera.get(), field ? &*field : nullptr);
  const auto background =
      UseCameraBackground(o.background && video != nullptr, o.video, camera.get(), &detector);

  DetectEvalResult result;
  std::unique_ptr<util::AtomicOutput> cand_file;
  std::unique_ptr<util::CsvWriter> cand_csv;
  if (!o.candidates_out.empty()) OpenCandidatesCsv(o.candidates_out, &cand_file, &cand_csv);
  if (o.on_start) o.on_start();
  util::Progress progress("eval detect", std::ssize(items), "images", o.progress);
  io::Frame frame;
  for (size_t i = 0; i < items.size(); ++i) {
    const LabelledImage& item = items[i];
    cv::Mat bgr;
    // A video's frames are read in turn; an image file not judged need not be read.
    if ((item.judged || video != nullptr) &&
        !NextImage(video.get(), item, camera.get(), o.camera, &frame, &bgr)) {
      items.resize(i);
      break;
    }
    if (!item.judged) {
      ++result.not_judged;
      progress.Update(static_cast<long long>(i) + 1);
      continue;
    }
    std::vector<cv::Rect2d> boxes = item.boxes;
    if (o.transform) TransformImage(o.transform, &bgr, &boxes);
    const auto candidates = detector.Detect(bgr);
    DetectEvalImage r = ScoreImage(candidates, boxes, o.grow);
    if (cand_csv != nullptr) {
      for (const auto& c : candidates) {
        const bool on_ball = BoxHolding(boxes, o.grow, c.centre_px.x(), c.centre_px.y()) != nullptr;
        *cand_csv << item.image << c.centre_px.x() << c.centre_px.y() << c.radius_px << c.score
                  << int(c.accepted) << int(c.weak) << int(on_ball) << c.visible_fraction
                  << c.inlier_fraction << c.outside_fraction << c.dents << int(c.region_ok)
                  << c.arc_cover << c.fill << c.spill << c.leak << c.contrast << c.region_outside
                  << c.region_extent << int(c.precise) << c.hue_contrast << c.network_score
                  << c.field_share << int(c.rescued) << int(c.apart_from_background)
                  << ReplaceCommas(c.reason);
        cand_csv->EndRow();
      }
    }
    r.image = item.image;
    if (drawings != nullptr) drawings->Add(static_cast<int>(i), item, r, candidates, bgr, o.grow);
    result.with_ball += r.boxes > 0;
    result.detected += r.detected;
    result.hits += r.hit;
    result.false_detections += r.detected && !r.hit;
    result.no_label_file += !item.has_label_file;
    result.images.push_back(std::move(r));
    progress.Update(static_cast<long long>(i) + 1);
  }
  progress.Finish();
  result.seconds = progress.ElapsedSeconds();
  result.background = NeededBackgroundSummary(background);
  result.camera_note = camera_note;
  if (drawings != nullptr) {
    result.drawn = drawings->written();
    result.drawn_dir = drawings->dir();
  }
  if (cand_csv != nullptr) {
    cand_file->CloseAndCommit(*cand_csv);
  }
  if (!o.out.empty()) {
    util::AtomicWrite(o.out, [&](const std::string& tmp) {
      util::CsvWriter w(tmp, {"image", "boxes", "detected", "hit", "u", "v", "radius_px", "score",
                              "centre_err_px", "candidate_on_ball", "accepted_on_ball",
                              "ball_radius_px", "reason"});
      for (const auto& im : result.images) {
        w << im.image << im.boxes << int(im.detected) << int(im.hit) << im.u << im.v << im.radius_px
          << im.score << im.centre_err_px << int(im.candidate_on_ball) << int(im.accepted_on_ball)
          << im.ball_radius_px << ReplaceCommas(im.reason);
        w.EndRow();
      }
      w.Close();
    });
  }
  if (drawings != nullptr) drawings->Keep();  // every output written
  return result;
}

}  // namespace fv::detect
