// `fieldvision color learn`: a colour class from pixels a user points at (colour_learn.h).
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "fieldvision/app/command.h"
#include "fieldvision/detect/colour_learn.h"
#include "fieldvision/detect/detect_eval.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::app {
namespace {

struct ColorLearnArgs {
  std::string video;
  std::string labels;
  int class_id = 0;
  std::string label_cam;
  int max_frames = 200;
  int frame = 0;
  std::string points;
  std::string roi;
  std::string negatives;
  std::string out;
  std::string mask_out;
  bool force = false;
  detect::ColourLearnOptions learn;
};

// --mask-out, else OUT-mask.png beside --out.
std::string MaskPath(const ColorLearnArgs& a) {
  if (!a.mask_out.empty()) return a.mask_out;
  const std::filesystem::path p(a.out);
  return (p.parent_path() / (p.stem().string() + "-mask.png")).string();
}

// Writes the colour file unless the class is bad (then only with --force), the overlay, and the
// purity report.
void WriteLearned(const ColorLearnArgs& a, const detect::ColourLearnResult& r,
                  const std::string& from, const std::string& advice) {
  std::cout << from << r.Summary() << "\n" << std::flush;
  if (!r.bad || a.force) detect::WriteColourSpec(r.spec, a.out);
  const std::string mask_out = MaskPath(a);
  io::WriteImage(mask_out, r.overlay);
  FV_REQUIRE(!r.bad || a.force,
             "colour class selects {:.1f} % of the background: {} not written (see {}; {}, or "
             "--force to write it anyway)",
             100 * r.negative_rate, a.out, mask_out, advice);
  std::cout << "wrote " << a.out << " (use it with --color " << a.out << ") and " << mask_out
            << " (what the class selects)\n";
}

// The balls' boxes of a labelled folder, glob or video (detect_eval.h), up to --max-frames of
// the frames with a ball, evenly spread.
void LearnFromLabels(const ColorLearnArgs& a) {
  FV_REQUIRE(a.points.empty() && a.roi.empty() && a.negatives.empty(),
             "--labels learns from the labelled boxes: leave out --points, --roi and --negative");
  const std::vector<detect::LabelledImage> items =
      detect::ListLabelledImages(a.video, {a.labels, a.class_id, a.label_cam}, "color learn");
  std::vector<const detect::LabelledImage*> with_ball;
  for (const detect::LabelledImage& item : items) {
    if (!item.boxes.empty()) with_ball.push_back(&item);
  }
  FV_REQUIRE(!with_ball.empty(), "color learn: no box of class {} in the labels of '{}'",
             a.class_id, a.video);
  const size_t n = std::min(with_ball.size(), static_cast<size_t>(a.max_frames));
  std::vector<const detect::LabelledImage*> chosen;
  chosen.reserve(n);
  for (size_t k = 0; k < n; ++k) chosen.push_back(with_ball[k * with_ball.size() / n]);
  // A video's frames in one pass.
  std::vector<cv::Mat> video_frames;
  if (chosen.front()->frame >= 0) {
    std::vector<int> indices;
    indices.reserve(n);
    for (const detect::LabelledImage* item : chosen) indices.push_back(item->frame);
    video_frames = detect::ReadVideoFrames(a.video, indices);
  }
  std::vector<detect::ColourLearnSample> samples;
  int boxes = 0;
  for (size_t k = 0; k < n; ++k) {
    const detect::LabelledImage& item = *chosen[k];
    detect::ColourLearnSample sample;
    sample.bgr = item.frame >= 0 ? video_frames[k] : io::ReadImage(item.image);
    const cv::Rect inside(0, 0, sample.bgr.cols, sample.bgr.rows);
    for (const cv::Rect2d& b : item.boxes) {
      const cv::Rect r = cv::Rect(cv::Point(cvRound(b.x), cvRound(b.y)),
                                  cv::Point(cvRound(b.x + b.width), cvRound(b.y + b.height))) &
                         inside;
      if (r.width >= 3 && r.height >= 3) sample.boxes.push_back(r);
    }
    if (sample.boxes.empty()) continue;  // boxes of a pixel or two, or outside the image
    boxes += static_cast<int>(sample.boxes.size());
    samples.push_back(std::move(sample));
  }
  FV_REQUIRE(!samples.empty(), "color learn: every labelled box in '{}' is under 3 x 3 pixels",
             a.video);
  const detect::ColourLearnResult r = detect::LearnColour(samples, a.learn);
  WriteLearned(a, r,
               fmt::format("learned from {} boxes in {} of the {} frames with a ball\n", boxes,
                           samples.size(), with_ball.size()),
               "learn from fewer frames of one light (one venue, one camera) or tighter boxes");
}

void Learn(const ColorLearnArgs& a) {
  if (!a.labels.empty()) {
    LearnFromLabels(a);
    return;
  }
  detect::ColourLearnOptions o = a.learn;
  FV_REQUIRE(!a.points.empty() || !a.roi.empty(),
             "give --points u,v;u,v..., --roi x,y,w,h or --labels DIR_OR_CSV");
  if (!a.points.empty()) o.points = detect::ParsePoints(a.points, "--points");
  if (!a.roi.empty()) o.roi = detect::ParseRect(a.roi, "--roi");
  if (!a.negatives.empty()) o.negative_points = detect::ParsePoints(a.negatives, "--negative");
  const cv::Mat frame = detect::ReadVideoFrame(a.video, a.frame);
  // Pixels outside the frame: name the option they came from.
  const cv::Rect inside(0, 0, frame.cols, frame.rows);
  FV_REQUIRE(!o.roi || (o.roi->area() > 0 && (*o.roi & inside) == *o.roi),
             "--roi {} is not inside the {}x{} frame", a.roi, frame.cols, frame.rows);
  for (const auto& [list, what] :
       {std::pair{&o.points, "--points"}, {&o.negative_points, "--negative"}}) {
    for (const Eigen::Vector2d& p : *list) {
      FV_REQUIRE(p.x() >= 0 && p.y() >= 0 && p.x() < frame.cols && p.y() < frame.rows,
                 "{}: pixel ({}, {}) is not inside the {}x{} frame", what, p.x(), p.y(), frame.cols,
                 frame.rows);
    }
  }
  WriteLearned(a, detect::LearnColour(frame, o), "",
               "point at the ball more tightly or add --negative");
}

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "color");
  auto a = std::make_shared<ColorLearnArgs>();
  CLI::App* learn = group->add_subcommand(
      "learn",
      "Learn a colour class from pixels you point at; writes a colour file and an image "
      "of what it selects");
  learn
      ->add_option("--video", a->video,
                   "Video file or image pattern (or a single image); with --labels also a folder "
                   "of images")
      ->required();
  learn->add_option("--labels", a->labels,
                    "Learn from labelled boxes instead of --points/--roi: a folder of YOLO txt "
                    "files (one per image) or a CSV image|frame,x,y,w,h (boxes across a video's "
                    "frames)");
  learn->add_option("--class", a->class_id, "With --labels: the YOLO class of the ball")
      ->check(FiniteRange(0, 1e6))
      ->capture_default_str();
  learn->add_option("--label-cam", a->label_cam,
                    "With --labels synth's truth_2d.csv: the camera whose rows label the video "
                    "(default: the video's name, else its folder's)");
  learn
      ->add_option("--max-frames", a->max_frames,
                   "With --labels: learn from at most this many frames with a ball, evenly spread")
      ->check(FiniteRange(1, 1e6))
      ->capture_default_str();
  learn->add_option("--frame", a->frame, "Frame number (from 0)")
      ->check(FiniteRange(0, 1e9))
      ->capture_default_str();
  learn->add_option("--points", a->points, "Pixels on the ball: \"u,v;u,v;...\"");
  learn->add_option("--roi", a->roi, "Box around the ball: x,y,w,h");
  learn->add_option("--negative", a->negatives,
                    "Pixels that are not the class: \"u,v;u,v;...\" (default: the frame away "
                    "from the ball)");
  learn->add_option("--name", a->learn.class_name, "Class name")->capture_default_str();
  learn
      ->add_option("--max-background", a->learn.max_background_share,
                   "Largest share of the background the class may select before it is bad")
      ->check(FiniteRange(0, 1))
      ->capture_default_str();
  learn->add_flag("--force", a->force, "Write the colour file even when the class is bad");
  learn->add_option("--out", a->out, "Colour file to write (JSON)")->required();
  learn->add_option("--mask-out", a->mask_out, "Image of the selection (default: OUT-mask.png)");
  learn->callback([a] {
    util::CheckOutputPath(a->out, {a->video, a->labels});
    util::CheckOutputPath(MaskPath(*a), {a->video, a->labels, a->out}, "--mask-out");
    // A device, a folder or a missing folder as an output is refused before any work.
    util::ResolveOutputPath(a->out);
    util::ResolveOutputPath(MaskPath(*a), "--mask-out");
    Learn(*a);
  });
  (void)exit_code;
}

FV_REGISTER_COMMAND(30, "color", Setup);

}  // namespace
}  // namespace fv::app
