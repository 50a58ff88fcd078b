#include "fieldvision/track/motion_file.h"

#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fieldvision/camera/frame_size.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/output_path.h"

namespace fv::track {

namespace {

constexpr const char* kFormat = "fieldvision camera motion 1";

bool SameLens(const camera::Camera& a, const camera::Camera& b) {
  const auto close = [](double x, double y) {
    return std::abs(x - y) <= 1e-9 * std::max({1.0, std::abs(x), std::abs(y)});
  };
  if (a.width != b.width || a.height != b.height || !close(a.fx, b.fx) || !close(a.fy, b.fy) ||
      !close(a.cx, b.cx) || !close(a.cy, b.cy)) {
    return false;
  }
  for (size_t i = 0; i < std::max(a.distortion.size(), b.distortion.size()); ++i) {
    const double da = i < a.distortion.size() ? a.distortion[i] : 0.0;
    const double db = i < b.distortion.size() ? b.distortion[i] : 0.0;
    if (!close(da, db)) return false;
  }
  return true;
}

}  // namespace

std::string MotionPathFor(const std::string& tracks_path) { return tracks_path + ".motion.json"; }

void WriteMotionFile(const ViewCanvas& canvas, const std::string& path) {
  const camera::Camera& lens = canvas.lens();
  nlohmann::json frames = nlohmann::json::array();
  for (int i = 0; i < canvas.frames(); ++i) {
    const cv::Matx33d h = canvas.FirstFromFrame(i);
    frames.push_back(std::vector<double>(h.val, h.val + 9));
  }
  const nlohmann::json j = {{"format", kFormat},
                            {"width", lens.width},
                            {"height", lens.height},
                            {"fx", lens.fx},
                            {"fy", lens.fy},
                            {"cx", lens.cx},
                            {"cy", lens.cy},
                            {"distortion", lens.distortion},
                            {"canvas_margin", canvas.margin()},
                            {"first_from_frame", frames}};
  util::WriteTextFile(path, j.dump(1) + "\n", "the camera motion file");
}

ViewCanvas ReadMotionFile(const std::string& path, const camera::Camera* posed,
                          const std::string& posed_what) {
  const nlohmann::json j = util::ReadJsonFile(path, "camera motion");
  const std::string ctx = fmt::format("camera motion file '{}'", path);
  FV_REQUIRE(j.is_object(), "{}: expected a JSON object", ctx);
  util::JsonKnownKeys(j, ctx,
                      {"format", "width", "height", "fx", "fy", "cx", "cy", "distortion",
                       "canvas_margin", "first_from_frame"});
  FV_REQUIRE(util::JsonString(j, "format", ctx) == kFormat, "{}: format must be '{}'", ctx,
             kFormat);
  camera::Camera lens;
  lens.name = "lens";
  lens.width = util::JsonInt(j, "width", ctx);
  lens.height = util::JsonInt(j, "height", ctx);
  lens.fx = util::JsonNumber(j, "fx", ctx);
  lens.fy = util::JsonNumber(j, "fy", ctx);
  lens.cx = util::JsonNumber(j, "cx", ctx);
  lens.cy = util::JsonNumber(j, "cy", ctx);
  lens.distortion = util::JsonNumbers(j, "distortion", ctx, false);
  lens.Check(ctx);
  if (posed != nullptr) {
    // players fitted the camera file to its video (an encoder's cropped padding): so is it here.
    camera::Camera fitted = *posed;
    if (camera::IsCroppedPadding(fitted, lens.width, lens.height)) {
      fitted.width = lens.width;
      fitted.height = lens.height;
    }
    FV_REQUIRE(SameLens(lens, fitted),
               "{}: the tracks were registered through another lens than {} ({}x{}, fx {:.6g} "
               "against {}x{}, fx {:.6g})",
               ctx, posed_what, lens.width, lens.height, lens.fx, posed->width, posed->height,
               posed->fx);
    lens = fitted;
  }
  const double margin = util::JsonNumber(j, "canvas_margin", ctx);
  const nlohmann::json& frames = util::JsonArray(j, "first_from_frame", ctx);
  FV_REQUIRE(!frames.empty(), "{}: first_from_frame has no frame", ctx);
  std::vector<cv::Matx33d> first_from_frame;
  for (size_t i = 0; i < frames.size(); ++i) {
    const std::vector<double> v =
        util::JsonFixedNumbers(frames[i], 9, fmt::format("{}: first_from_frame[{}]", ctx, i));
    first_from_frame.emplace_back(v.data());
  }
  // The canvas's own checks (margin, homographies) name the file too.
  try {
    ViewCanvas canvas(lens, margin);
    for (const cv::Matx33d& h : first_from_frame) canvas.AddFrame(h);
    return canvas;
  } catch (const Error& e) {
    Throw("{}: {}", ctx, e.what());
  }
}

std::optional<ViewCanvas> ReadMotionFor(const std::string& tracks_path, const camera::Camera* posed,
                                        const std::string& posed_what) {
  const std::string path = MotionPathFor(tracks_path);
  if (!std::filesystem::exists(path)) return std::nullopt;
  return ReadMotionFile(path, posed, posed_what);
}

std::string CarryMotionTo(const std::string& tracks_path, const std::string& from) {
  if (from.empty()) return SaveMotionFor(tracks_path, nullptr);
  const std::string path = MotionPathFor(tracks_path);
  util::AtomicWrite(
      path,
      [&from](const std::string& temp) {
        std::error_code ec;
        std::filesystem::copy_file(from, temp, std::filesystem::copy_options::overwrite_existing,
                                   ec);
        FV_REQUIRE(!ec, "cannot copy the camera motion file '{}': {}", from, ec.message());
      },
      "the camera motion file");
  return fmt::format("wrote {} (the camera's motion of {}, read by tracks draw)", path, from);
}

std::string SaveMotionFor(const std::string& tracks_path, const ViewCanvas* canvas) {
  const std::string path = MotionPathFor(tracks_path);
  if (canvas != nullptr) {
    WriteMotionFile(*canvas, path);
    return fmt::format("wrote {} (the camera's motion, read by tracks draw)", path);
  }
  if (!util::RemoveEarlierFile(path, "motion file")) return "";
  return fmt::format("removed {} (an earlier run's camera motion: this camera stood still)", path);
}

}  // namespace fv::track
