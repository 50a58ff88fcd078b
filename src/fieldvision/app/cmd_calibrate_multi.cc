// `fieldvision calibrate multi`: intrinsics and relative poses of 2..N cameras from synchronized
// views of one board (calib/multi.h); writes DIR/NAME.yaml per camera (pose in the first camera's
// frame), DIR/NAME_coverage.png, DIR/corners.csv and DIR/calibration.toml (Pose2Sim/anipose).
#include <filesystem>
#include <iostream>
#include <memory>

#include <fmt/format.h>

#include "fieldvision/app/camera_folder.h"
#include "fieldvision/app/cmd_calibrate_board.h"
#include "fieldvision/app/command.h"
#include "fieldvision/calib/import.h"
#include "fieldvision/calib/multi.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/util/error.h"

namespace fv::app {
namespace {

using fv::calib::CameraViews;
using fv::calib::ImageSource;
using fv::calib::MultiCoveragePicture;
using fv::calib::MultiOptions;
using fv::calib::MultiResult;
using fv::calib::ParseCameraViews;
using fv::calib::ParsePairing;
using fv::calib::ParseTangentialModel;
using fv::calib::TangentialModel;
using fv::calib::WriteCalibrationToml;
using fv::calib::WriteMultiCorners;

struct MultiCli {
  std::string out, pairing = "auto", tangential = "auto", k3 = "auto";
  BoardCli board;
  std::vector<std::string> views, intrinsics;
  bool fix_intrinsics = false, zero_tangent = false, quiet = false, no_pictures = false;
  MultiOptions o;
};

void RunMulti(MultiCli& c) {
  c.o.board = c.board.Spec();
  c.o.pairing = ParsePairing(c.pairing);
  c.o.progress = !c.quiet;
  c.o.refine_intrinsics = !c.fix_intrinsics;
  FV_REQUIRE(!c.zero_tangent || c.tangential == "auto" || c.tangential == "zero",
             "--zero-tangent is --tangential zero: it does not go with --tangential {}",
             c.tangential);
  c.o.tangential = c.zero_tangent ? TangentialModel::kZero : ParseTangentialModel(c.tangential);
  CheckK3Model(c.k3, c.o.num_distortion);
  c.o.k3 = fv::calib::ParseK3Model(c.k3);
  std::vector<CameraViews> cams;
  std::vector<std::string> inputs;  // views and known intrinsics: no output may replace one
  for (const auto& v : c.views) {
    cams.push_back(ParseCameraViews(v));
    inputs.push_back(cams.back().source);
  }
  for (const auto& k : c.intrinsics) {
    const CameraViews kv = ParseCameraViews(k);  // NAME=CAM.yaml
    const auto view = std::find_if(cams.begin(), cams.end(),
                                   [&](const CameraViews& v) { return v.name == kv.name; });
    FV_REQUIRE(view != cams.end(), "--intrinsics '{}': no --views names camera '{}'", k, kv.name);
    const camera::Camera known = camera::ReadCameraYaml(kv.source);
    // A camera file of another image size is refused before the board search, not after it.
    const ImageSource source(view->source, c.o.source);
    const cv::Mat first = source.Read(0);
    FV_REQUIRE(first.cols == known.width && first.rows == known.height,
               "--intrinsics '{}': camera file '{}' is for {}x{} images but the views of '{}' "
               "('{}') are {}x{}",
               k, kv.source, known.width, known.height, kv.name, view->source, first.cols,
               first.rows);
    c.o.known_intrinsics[kv.name] = known;
    inputs.push_back(kv.source);
  }
  c.o.Check();
  {  // The camera files go to --out as NAME.yaml: checked before the board search.
    std::vector<camera::Camera> named(cams.size());
    for (size_t i = 0; i < cams.size(); ++i) named[i].name = cams[i].name;
    CameraFilePaths(named, c.out, "--out", inputs);
  }
  const MultiResult r = CalibrateMulti(cams, c.o);

  std::cout << fmt::format("{:<12s} {:>6s} {:>6s} {:>6s} {:>9s} {:>9s} {:>9s} {:>9s} {:>9s}  {}\n",
                           "camera", "images", "found", "used", "rms_px", "fx", "fy", "cx", "cy",
                           "chained from");
  for (size_t i = 0; i < r.cameras.size(); ++i) {
    const auto& rep = r.camera_reports[i];
    const camera::Camera& cam = r.cameras[i];
    std::cout << fmt::format(
        "{:<12s} {:>6d} {:>6d} {:>6d} {:>9.3f} {:>9.2f} {:>9.2f} {:>9.2f} {:>9.2f}  {}\n", rep.name,
        rep.num_images, rep.num_found, rep.num_used, rep.rms_px, cam.fx, cam.fy, cam.cx, cam.cy,
        rep.tree_parent < 0
            ? std::string("(reference)")
            : fmt::format("{} ({} shared views)", r.camera_reports[rep.tree_parent].name,
                          rep.tree_shared_views));
  }
  std::cout << "\ndistortion model:\n";
  for (const auto& rep : r.camera_reports) {
    std::cout << fmt::format("  {:<12s} {}", rep.name, rep.model);
    if (rep.own_k3_corner_shift_px > 0) {
      std::cout << fmt::format(
          "; alone, its fits with and without k3 put the image corners {:.1f} px apart (the "
          "model is extrapolated where its boards did not reach)",
          rep.own_k3_corner_shift_px);
    }
    std::cout << "\n";
  }
  std::cout << fmt::format("\n{:<24s} {:>12s} {:>12s} {:>7s}\n", "pair", "rotation_deg",
                           "baseline_mm", "shared");
  for (const auto& p : r.pairs) {
    std::cout << fmt::format("{:<24s} {:>12.3f} {:>12.2f} {:>7d}\n",
                             r.camera_reports[p.i].name + " - " + r.camera_reports[p.j].name,
                             p.rotation_deg, 1000 * p.baseline_m, p.shared_views);
    if (p.has_opencv) {
      std::cout << fmt::format(
          "{:<24s} {:>12.3f} {:>12.2f}          (OpenCV stereoCalibrate, rms {:.3f} px: "
          "rotations differ by {:.3f} deg, baselines by {:+.2f} %)\n",
          "", p.opencv_rotation_deg, 1000 * p.opencv_baseline_m, p.opencv_rms_px,
          p.opencv_rotation_diff_deg,
          100 * (p.baseline_m - p.opencv_baseline_m) / p.opencv_baseline_m);
    }
  }
  bool any_dropped = false;
  for (const auto& v : r.views) {
    if (v.used) continue;
    if (!any_dropped) std::cout << "\ndropped views:\n";
    any_dropped = true;
    std::cout << fmt::format("  {} ({}): {}\n", v.name, r.camera_reports[v.camera].name,
                             v.dropped_because);
  }
  std::cout << fmt::format(
      "\n{} moments with the board ({}); rms {:.3f} px over all used corners; bundle adjustment "
      "cost {:.4g} -> {:.4g} in {} iterations\n",
      r.num_frames, r.pairing, r.rms_px, r.initial_cost, r.final_cost, r.iterations);
  for (const auto& w : r.warnings) std::cerr << "warning: " << w << "\n";

  namespace fs = std::filesystem;
  const std::vector<std::string> paths = CameraFilePaths(r.cameras, c.out, "--out", inputs);
  fs::create_directories(c.out);
  for (size_t i = 0; i < r.cameras.size(); ++i) {
    const std::string& path = paths[i];
    camera::WriteCameraYaml(r.cameras[i], path);
    std::cout << "wrote " << path << "\n";
    if (!c.no_pictures) {
      const std::string pic =
          path.substr(0, path.size() - std::string(".yaml").size()) + "_coverage.png";
      io::WriteImage(pic, MultiCoveragePicture(r, static_cast<int>(i)));
      std::cout << "wrote " << pic << "\n";
    }
  }
  const std::string corners = (fs::path(c.out) / "corners.csv").string();
  WriteMultiCorners(corners, r);
  const std::string toml = (fs::path(c.out) / "calibration.toml").string();
  WriteCalibrationToml(r.cameras, toml);
  std::cout << "wrote " << corners << "\nwrote " << toml << "\n";
}

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "calibrate");
  auto c = std::make_shared<MultiCli>();
  CLI::App* cmd = group->add_subcommand(
      "multi",
      "Intrinsics and relative poses of 2..N cameras from synchronized views of one board");
  AddBoardOptions(cmd, c->board);
  cmd->add_option("--views", c->views,
                  "NAME=GLOB_OR_DIR_OR_VIDEO, one per camera (repeat); the first is the reference")
      ->required();
  cmd->add_option("--pairing", c->pairing,
                  "auto (frame number when every file name has one, else sorted order), order or "
                  "frame")
      ->check(CLI::IsMember({"auto", "order", "frame", "frame-number"}, CLI::ignore_case))
      ->capture_default_str();
  cmd->add_option("--intrinsics", c->intrinsics,
                  "NAME=CAM.yaml: known intrinsics of a camera, kept fixed (repeat)");
  cmd->add_flag("--fix-intrinsics", c->fix_intrinsics,
                "Keep every camera's own intrinsics fixed in the joint adjustment");
  AddBoardFitOptions(cmd, c->o);
  cmd->add_option("--tangential", c->tangential,
                  "Tangential distortion p1 p2: auto (per camera, kept only where it lowers the "
                  "reprojection error by more than its 2 parameters cost: BIC), free or zero")
      ->check(CLI::IsMember({"auto", "free", "zero"}, CLI::ignore_case))
      ->capture_default_str();
  cmd->add_flag("--zero-tangent", c->zero_tangent, "The same as --tangential zero");
  cmd->add_option("--k3", c->k3,
                  "With --model 5, the r^6 term k3 per camera: auto (kept only on very strong "
                  "evidence, BIC gain over 10: boards that stay off the image corners extrapolate "
                  "k3 there), free (OpenCV's) or zero")
      ->check(CLI::IsMember({"auto", "free", "zero"}))
      ->capture_default_str();
  cmd->add_option("--loss-px", c->o.loss_px, "Huber scale of the bundle adjustment in pixels")
      ->check(FiniteRange(0.01, 1000))
      ->capture_default_str();
  cmd->add_option("--min-shared", c->o.min_shared_views,
                  "Views two cameras must share to be linked")
      ->check(FiniteRange(1, 100000))
      ->capture_default_str();
  cmd->add_option("--out", c->out, "Folder for NAME.yaml per camera and the pictures")->required();
  cmd->add_flag("--no-pictures", c->no_pictures, "Do not write the coverage pictures");
  cmd->add_flag("--compare-opencv", c->o.compare_opencv,
                "Also run OpenCV's stereoCalibrate on every camera pair and print the differences");
  cmd->add_flag("--quiet", c->quiet, "No progress");
  cmd->callback([c] { RunMulti(*c); });
  (void)exit_code;
}

FV_REGISTER_COMMAND(22, "calibrate multi", Setup);

}  // namespace
}  // namespace fv::app
