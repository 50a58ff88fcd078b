// `fieldvision calibrate intrinsics|extrinsics|refine|check|rig`: parse options, call the
// calibration library (src/fieldvision/calib), print the numbers and write the camera files.
// `extrinsics` also places a whole rig (--rig DIR, calib/rig_place.h), calibrates a camera without
// intrinsics from the field alone (--image-size, calib/focal.h) or fits the ground homography
// (--homography-only); `refine --rig DIR` carries the rig with the refined camera.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>

#include <fmt/format.h>

#include "fieldvision/app/camera_folder.h"
#include "fieldvision/app/cmd_calibrate_board.h"
#include "fieldvision/app/command.h"
#include "fieldvision/calib/check.h"
#include "fieldvision/calib/extrinsics.h"
#include "fieldvision/calib/focal.h"
#include "fieldvision/calib/import.h"
#include "fieldvision/calib/intrinsics.h"
#include "fieldvision/calib/lines.h"
#include "fieldvision/calib/rig.h"
#include "fieldvision/calib/rig_lines.h"
#include "fieldvision/calib/rig_place.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/camera/frame_size.h"
#include "fieldvision/camera/pose_range.h"
#include "fieldvision/field/field.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::app {
namespace {

// `camera` fitted to `image` (camera::FitCameraToFrames: an encoder's cropped padding), the note
// printed; another size is an error naming both.
void FitToImage(const cv::Mat& image, const std::string& image_path, camera::Camera& camera,
                const std::string& camera_what) {
  const std::string note = camera::FitCameraToFrames(camera, camera_what, image.cols, image.rows,
                                                     fmt::format("image '{}'", image_path));
  if (!note.empty()) std::cout << note << "\n";
}

using calib::CheckCalibration;
using calib::CheckOptions;
using calib::CheckResult;
using calib::ExtrinsicsOptions;
using calib::ExtrinsicsResult;
using calib::FocalOptions;
using calib::FocalResult;
using calib::HomographyResult;
using calib::IntrinsicsOptions;
using calib::IntrinsicsResult;
using calib::ParseImageSize;
using calib::PointCorrespondence;
using calib::PointResidual;
using calib::ReadPointsCsv;
using calib::ReadRigObservations;
using calib::RefineOptions;
using calib::RefineResult;
using calib::RefineRigWithLines;
using calib::RigObservation;
using calib::RigOptions;
using calib::RigPlacementOptions;
using calib::RigPlacementResult;
using calib::RigRefineResult;
using calib::RigResult;
using calib::WriteHomographyYaml;
using calib::WritePointErrorTable;

cv::Mat ReadImage(const std::string& path) {
  FV_REQUIRE(!std::filesystem::is_directory(path), "image '{}' is a folder, not an image file",
             path);
  FV_REQUIRE(std::filesystem::is_regular_file(path), "image '{}' does not exist", path);
  cv::Mat image = io::TryReadImage(path);
  FV_REQUIRE(!image.empty(), "image '{}' cannot be read (corrupt or not an image)", path);
  return image;
}

void Warn(const std::string& message) { std::cerr << "warning: " << message << "\n"; }

// Many clicked points that fit no pose are more often the wrong field or misnamed points than
// bad clicks: said when 30 % or more were left out.
void WarnManyOutliers(size_t points, size_t inliers, const field::FieldModel* field) {
  if (points == 0 || inliers >= points || (points - inliers) * 10 < points * 3) return;
  Warn(fmt::format(
      "{} of the {} points fit no pose together with the others: are the points' names those "
      "of {} (`fieldvision field show --field NAME` lists them), and their x, y, z metres?",
      points - inliers, points,
      field != nullptr ? "field '" + field->name + "'" : "the field they were clicked on"));
}

// A refined pose whose line error is above this (mean, mm) likely has the wrong frame or field.
constexpr double kLooseLinesMm = 50.0;

// The rig camera named by `which`: a camera name or the path/stem of one of its files.
int FindRigCamera(const std::vector<camera::Camera>& rig, const std::string& which,
                  const std::string& dir) {
  const std::string stem = std::filesystem::path(which).stem().string();
  for (size_t i = 0; i < rig.size(); ++i) {
    if (rig[i].name == which || rig[i].name == stem) return static_cast<int>(i);
  }
  std::string names;
  for (const auto& c : rig) names += (names.empty() ? "" : ", ") + c.name;
  Throw("rig '{}' has no camera '{}' (its cameras: {})", dir, which, names);
}

// Frames of a rig's cameras from --image NAME=FRAME (or FRAME for the --camera NAME); empty for
// cameras without a frame; names[i] the file of camera i's frame. A camera is fitted to its frame
// (camera::FitCameraToFrames: an encoder's cropped padding, noted; else an error).
std::vector<cv::Mat> ReadRigFrames(std::vector<camera::Camera>& rig,
                                   const std::vector<std::string>& images,
                                   const std::string& camera, const std::string& dir,
                                   std::vector<std::string>* names) {
  std::vector<cv::Mat> frames(rig.size());
  names->assign(rig.size(), "");
  for (const auto& arg : images) {
    const size_t eq = arg.find('=');
    int k;
    std::string file;
    if (eq == std::string::npos) {
      FV_REQUIRE(!camera.empty(),
                 "--image '{}': with --rig give NAME=FRAME (NAME a camera of the rig) or --camera "
                 "NAME",
                 arg);
      k = FindRigCamera(rig, camera, dir);
      file = arg;
    } else {
      k = FindRigCamera(rig, arg.substr(0, eq), dir);
      file = arg.substr(eq + 1);
    }
    FV_REQUIRE(frames[k].empty(), "--image: two frames for rig camera '{}' ('{}' and '{}')",
               rig[k].name, (*names)[k], file);
    frames[k] = ReadImage(file);
    FitToImage(frames[k], file, rig[k], fmt::format("camera '{}'", rig[k].name));
    (*names)[k] = file;
  }
  return frames;
}

// Prints a rig refinement's report and notes it in the camera files.
std::vector<camera::Camera> ReportRigRefinement(const RigRefineResult& r,
                                                const std::vector<cv::Mat>& frames,
                                                const std::vector<std::string>& names) {
  std::cout << r.Summary() << "\n";
  for (size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].empty()) continue;
    std::cout << fmt::format(
        "line error {}: mean {:.1f} mm, p95 {:.1f} mm (before: mean {:.1f} mm, p95 {:.1f} mm)\n",
        r.cameras[i].name, r.after[i].mean_mm, r.after[i].p95_mm, r.before[i].mean_mm,
        r.before[i].p95_mm);
  }
  if (!r.accepted) Warn("rig not refined: " + r.status + "; the camera files keep the input poses");
  for (size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].empty() || r.after[i].num_inliers == 0 || r.after[i].mean_mm <= kLooseLinesMm) {
      continue;
    }
    Warn(
        fmt::format("{}'s field lines lie {:.0f} mm from the painted ones on average: is '{}' a "
                    "frame of that camera, and --field its field?",
                    r.cameras[i].name, r.after[i].mean_mm, names[i]));
  }
  std::vector<camera::Camera> out = r.cameras;
  if (!r.accepted) return out;
  const auto num_frames =
      std::count_if(frames.begin(), frames.end(), [](const cv::Mat& m) { return !m.empty(); });
  for (size_t i = 0; i < out.size(); ++i) {
    out[i].notes["refined_with_rig_lines"] = fmt::format("{} frames", num_frames);
    if (frames[i].empty()) continue;
    out[i].notes["refined_with_lines"] = names[i];
    out[i].notes["line_error_mean_mm"] = fmt::format("{:.1f}", r.after[i].mean_mm);
    out[i].notes["line_error_p95_mm"] = fmt::format("{:.1f}", r.after[i].p95_mm);
  }
  return out;
}

// The files of NAME=FILE arguments (a plain FILE stays as it is).
std::vector<std::string> FilesOf(const std::vector<std::string>& args) {
  std::vector<std::string> files;
  files.reserve(args.size());
  for (const auto& a : args) files.push_back(a.substr(a.find('=') + 1));
  return files;
}

// Where the cameras read from `camera_files` go in `out_dir`: each under its file's name, so
// that the output folder may be the cameras' own; checked before the work (CheckRigOutput naming
// `what`; `inputs`: the files the run reads besides the cameras).
std::vector<std::string> RigOutputPaths(const std::vector<std::string>& camera_files,
                                        const std::string& out_dir,
                                        const std::vector<std::string>& inputs,
                                        const std::string& what) {
  std::vector<std::string> paths;
  paths.reserve(camera_files.size());
  for (const std::string& f : camera_files) {
    paths.push_back(
        (std::filesystem::path(out_dir) / std::filesystem::path(f).filename()).string());
  }
  CheckRigOutput(paths, out_dir, inputs, what);
  return paths;
}

void WriteRig(const std::vector<camera::Camera>& cams, const std::vector<std::string>& paths,
              const std::string& dir) {
  FV_REQUIRE(cams.size() == paths.size(), "WriteRig: {} cameras but {} paths", cams.size(),
             paths.size());
  std::filesystem::create_directories(dir);
  for (size_t i = 0; i < cams.size(); ++i) {
    camera::WriteCameraYaml(cams[i], paths[i]);
    std::cout << "wrote " << paths[i] << "\n";
  }
}

// ---- intrinsics
struct IntrinsicsCli {
  std::string images, out, name;
  BoardCli board;
  IntrinsicsOptions o;
  std::string k3 = "auto";
  bool quiet = false;
};

void RunIntrinsics(IntrinsicsCli& c) {
  c.o.board = c.board.Spec();
  c.o.camera_name = c.name;
  c.o.progress = !c.quiet;
  CheckK3Model(c.k3, c.o.num_distortion);
  c.o.k3 = calib::ParseK3Model(c.k3);
  const IntrinsicsResult r = CalibrateIntrinsics(c.images, c.o);
  std::cout << fmt::format("{:<48s} {:>7s} {:>8s}  {}\n", "view", "corners", "rms_px", "status");
  for (const auto& v : r.views) {
    const std::string status = !v.board_found ? "no board"
                               : v.used       ? "used"
                                              : "dropped: " + v.dropped_because;
    std::cout << fmt::format("{:<48s} {:>7d} {:>8.3f}  {}\n", v.name, v.num_corners, v.rms_px,
                             status);
  }
  std::cout << "coverage: " << r.coverage.Describe() << "\n";
  std::cout << r.Summary() << "\n";
  for (const auto& w : r.warnings) Warn(w);
  camera::WriteCameraYaml(r.camera, c.out);
  std::cout << fmt::format("RMS reprojection error: {:.3f} px\nwrote {}\n", r.rms_px, c.out);
}

// ---- extrinsics
struct ExtrinsicsCli {
  std::string camera, field, out, table, rig, image_size;
  std::vector<std::string> points, images;
  bool k1 = false, homography_only = false;
  ExtrinsicsOptions o;
};

void PrintPointTable(const std::vector<PointResidual>& pts) {
  std::cout << fmt::format("{:<36s} {:>8s} {:>8s} {:>8s} {:>8s} {:>7s} {:>8s} {:>8s}  {}\n",
                           "point", "u", "v", "x_m", "y_m", "z_m", "err_px", "err_mm", "");
  for (const auto& p : pts) {
    std::cout << fmt::format(
        "{:<36s} {:>8.1f} {:>8.1f} {:>8.3f} {:>8.3f} {:>7.3f} {:>8.2f} {:>8s}  "
        "{}\n",
        p.name, p.uv_px.x(), p.uv_px.y(), p.p_world.x(), p.p_world.y(), p.p_world.z(), p.err_px,
        p.err_mm ? fmt::format("{:.0f}", *p.err_mm) : std::string("-"), p.inlier ? "" : "outlier");
  }
}

void PlaceRigOnField(const ExtrinsicsCli& c, const field::FieldModel* field) {
  const std::vector<camera::Camera> rig = ReadCameraFolder(c.rig, /*require_pose=*/true);
  const std::vector<std::string> paths =
      RigOutputPaths(CameraFilesIn(c.rig), c.out,
                     util::PathList(FilesOf(c.points), FilesOf(c.images), c.field), "--out");
  std::vector<std::vector<PointCorrespondence>> pts(rig.size());
  for (const auto& arg : c.points) {
    const size_t eq = arg.find('=');
    int k;
    std::string file;
    if (eq == std::string::npos) {
      FV_REQUIRE(!c.camera.empty(),
                 "--points '{}': with --rig give NAME=POINTS.csv (NAME a camera of the rig) or "
                 "--camera NAME",
                 arg);
      k = FindRigCamera(rig, c.camera, c.rig);
      file = arg;
    } else {
      k = FindRigCamera(rig, arg.substr(0, eq), c.rig);
      file = arg.substr(eq + 1);
    }
    const auto p = ReadPointsCsv(file, field, rig[k].width, rig[k].height);
    pts[k].insert(pts[k].end(), p.begin(), p.end());
  }
  RigPlacementOptions ro;
  ro.pnp = c.o;
  const RigPlacementResult r = PlaceRig(rig, pts, ro);
  for (size_t i = 0; i < rig.size(); ++i) {
    if (r.points[i].empty()) continue;
    std::cout << "camera " << rig[i].name << ":\n";
    PrintPointTable(r.points[i]);
  }
  std::cout << r.Summary() << "\n";
  std::cout << fmt::format("reprojection error: {:.2f} px rms\n", r.rms_px_all);
  if (r.num_inliers < r.num_points) {
    Warn(fmt::format("{} points did not fit and were left out (marked 'outlier')",
                     r.num_points - r.num_inliers));
  }
  WarnManyOutliers(r.num_points, r.num_inliers, field);
  std::vector<camera::Camera> out = r.cameras;
  for (const camera::Camera& cam : out) camera::CheckCameraNearOrigin(cam, "--rig " + c.rig);
  for (size_t i = 0; i < out.size(); ++i) {
    out[i].notes["placed_with_rig"] = c.rig;
    out[i].notes["rig_placement_rms_px"] = fmt::format("{:.3f}", r.rms_px_all);
  }
  if (!c.images.empty()) {
    // Then the lines in the given frames: a few clicks place the rig within centimetres, the
    // lines seen by its cameras within millimetres.
    FV_REQUIRE(field != nullptr, "--image with --rig refines against the lines: give --field");
    std::vector<std::string> names;
    const std::vector<cv::Mat> frames = ReadRigFrames(out, c.images, c.camera, c.rig, &names);
    out = ReportRigRefinement(RefineRigWithLines(out, frames, *field), frames, names);
  }
  WriteRig(out, paths, c.out);
}

void RunFocal(const ExtrinsicsCli& c, const field::FieldModel* field) {
  int w = 0, h = 0;
  ParseImageSize(c.image_size, "--image-size", &w, &h);
  const auto pts = ReadPointsCsv(c.points.front(), field, w, h);
  if (c.homography_only) {
    FV_REQUIRE(!c.k1, "--k1 goes with the focal length's fit, not with --homography-only");
    const HomographyResult r = EstimateGroundHomography(w, h, pts, c.o.ransac_threshold_px);
    PrintPointTable(r.points);
    std::cout << r.Summary() << "\n";
    WriteHomographyYaml(r, c.out);
    std::cout << "wrote " << c.out << "\n";
    return;
  }
  FocalOptions fo;
  fo.pnp = c.o;
  fo.outlier_px = c.o.ransac_threshold_px;  // --threshold: also the gate of the focal fit
  fo.estimate_k1 = c.k1;
  const FocalResult r = EstimateFocalAndPose(w, h, pts, fo);
  PrintPointTable(r.points);
  std::cout << r.Summary() << "\n";
  std::cout << fmt::format(
      "focal length: {:.1f} px +- {:.1f} px (1 sigma), horizontal field of view {:.2f} deg\n"
      "reprojection error: {:.2f} px rms\ncamera position: {:.3f} {:.3f} {:.3f} m (+- {:.3f} "
      "{:.3f} {:.3f} m)\n",
      r.camera.fx, r.std_focal_px, r.hfov_deg, r.rms_px, r.camera_position_m.x(),
      r.camera_position_m.y(), r.camera_position_m.z(), r.std_position_m.x(), r.std_position_m.y(),
      r.std_position_m.z());
  for (const auto& w2 : r.warnings) Warn(w2);
  WarnManyOutliers(pts.size(), r.num_inliers, field);
  camera::Camera out = r.camera;
  camera::CheckCameraNearOrigin(out, "--points " + c.points.front());
  out.rms_px = r.rms_px;
  out.notes["extrinsics_points"] = c.points.front();
  out.notes["focal_std_px"] = fmt::format("{:.2f}", r.std_focal_px);
  if (!c.table.empty()) WritePointErrorTable(c.table, r.points);
  camera::WriteCameraYaml(out, c.out);
  std::cout << "wrote " << c.out << "\n";
}

void RunExtrinsics(const ExtrinsicsCli& c) {
  std::unique_ptr<field::FieldModel> field;
  if (!c.field.empty()) field = std::make_unique<field::FieldModel>(field::LoadField(c.field));
  if (!c.rig.empty()) {
    FV_REQUIRE(c.image_size.empty() && !c.homography_only && !c.k1,
               "--rig places calibrated cameras; it does not go with --image-size, --k1 or "
               "--homography-only");
    PlaceRigOnField(c, field.get());
    return;
  }
  FV_REQUIRE(c.images.empty(), "--image goes with --rig (use calibrate refine for one camera)");
  FV_REQUIRE(c.points.size() == 1,
             "give one --points file (several only with --rig DIR, as NAME=POINTS.csv)");
  FV_REQUIRE(!c.camera.empty() || !c.image_size.empty(),
             "give --camera CAM.yaml (with intrinsics), or --image-size WxH to estimate the focal "
             "length from the points too");
  if (c.camera.empty()) {
    RunFocal(c, field.get());
    return;
  }
  FV_REQUIRE(c.image_size.empty() && !c.k1,
             "--image-size and --k1 estimate the focal length from the points; with --camera its "
             "intrinsics are used: give one or the other");
  FV_REQUIRE(!c.homography_only, "--homography-only goes with --image-size, not --camera");
  const camera::Camera cam = camera::ReadCameraYaml(c.camera);
  const auto pts = ReadPointsCsv(c.points.front(), field.get(), cam.width, cam.height);
  const ExtrinsicsResult r = EstimatePose(cam, pts, c.o);
  PrintPointTable(r.points);
  std::cout << r.Summary() << "\n";
  std::cout << fmt::format(
      "reprojection error: {:.2f} px rms\ncamera position: {:.3f} {:.3f} "
      "{:.3f} m\n",
      r.rms_px, r.camera_position_m.x(), r.camera_position_m.y(), r.camera_position_m.z());
  if (r.num_inliers < static_cast<int>(pts.size())) {
    Warn(fmt::format("{} points did not fit and were left out (marked 'outlier')",
                     pts.size() - r.num_inliers));
  }
  WarnManyOutliers(pts.size(), r.num_inliers, field.get());
  camera::Camera out = r.camera;
  camera::CheckCameraNearOrigin(out, "--points " + c.points.front());
  out.rms_px = r.rms_px;
  out.notes["extrinsics_points"] = c.points.front();
  out.notes["extrinsics_rms_px"] = fmt::format("{:.3f}", r.rms_px);
  if (!c.table.empty()) WritePointErrorTable(c.table, r.points);
  camera::WriteCameraYaml(out, c.out);
  std::cout << "wrote " << c.out << "\n";
}

// ---- refine
struct RefineCli {
  std::string camera, field, out, overlay, rig;
  std::vector<std::string> images;
  RefineOptions o;
};

void WriteOverlay(const std::string& path, const camera::Camera& cam, const cv::Mat& image,
                  const field::FieldModel& field, const RefineOptions& o) {
  CheckOptions co;
  co.detect = o.detect;
  io::WriteImage(path, CheckCalibration(cam, image, field, {}, co).overlay);
  std::cout << "wrote " << path << "\n";
}

// A rig on the field refined with the lines in frames of any of its cameras: one rigid
// correction for the whole rig (calib/rig_lines.h).
void RunRefineRig(const RefineCli& c) {
  std::vector<camera::Camera> rig = ReadCameraFolder(c.rig, /*require_pose=*/true);
  const std::vector<std::string> paths = RigOutputPaths(
      CameraFilesIn(c.rig), c.out, util::PathList(FilesOf(c.images), c.field), "--out");
  std::vector<std::string> names;
  const std::vector<cv::Mat> frames = ReadRigFrames(rig, c.images, c.camera, c.rig, &names);
  const field::FieldModel field = field::LoadField(c.field);
  const RigRefineResult r = RefineRigWithLines(rig, frames, field, c.o);
  const std::vector<camera::Camera> out = ReportRigRefinement(r, frames, names);
  WriteRig(out, paths, c.out);
  if (!c.overlay.empty()) {
    // The overlay of the first camera with a frame.
    for (size_t i = 0; i < rig.size(); ++i) {
      if (frames[i].empty()) continue;
      WriteOverlay(c.overlay, out[i], frames[i], field, c.o);
      break;
    }
  }
}

void RunRefine(const RefineCli& c) {
  if (!c.rig.empty()) {
    RunRefineRig(c);
    return;
  }
  FV_REQUIRE(!c.camera.empty(), "give --camera CAM.yaml (or --rig DIR with --image NAME=FRAME)");
  FV_REQUIRE(c.images.size() == 1,
             "give one --image for --camera (several only with --rig DIR, as NAME=FRAME)");
  camera::Camera cam = camera::ReadCameraYaml(c.camera);
  const std::string& image_path = c.images.front();
  const cv::Mat image = ReadImage(image_path);
  FitToImage(image, image_path, cam, fmt::format("camera file '{}'", c.camera));
  const field::FieldModel field = field::LoadField(c.field);
  const RefineResult r = RefineWithLines(cam, image, field, c.o);
  // No line pixel near a line: nothing to refine with, and no line error (0.0 mm read as perfect).
  FV_REQUIRE(r.accepted || r.before.num_inliers > 0,
             "calibrate refine: camera '{}' sees no line of field '{}' in '{}' ({} line pixels, "
             "none near a line): the pose or the field is wrong; nothing written",
             c.camera, field.name, image_path, r.before.num_pixels);
  // One report: the library's summary, then the contract's line error.
  std::cout << r.Summary() << "\n";
  std::cout << fmt::format(
      "line error: mean {:.1f} mm, p95 {:.1f} mm (before: mean {:.1f} mm, "
      "p95 {:.1f} mm)\n",
      r.after.mean_mm, r.after.p95_mm, r.before.mean_mm, r.before.p95_mm);
  if (!r.accepted) Warn("pose not refined: " + r.status + "; the camera file keeps the input pose");
  // A pose that fits the lines leaves them a few centimetres off at most (the renders: 6 mm).
  if (r.after.num_inliers > 0 && r.after.mean_mm > kLooseLinesMm) {
    Warn(
        fmt::format("the field's lines lie {:.0f} mm from the painted ones on average: is '{}' "
                    "a frame of this camera, and --field its field?",
                    r.after.mean_mm, image_path));
  }
  camera::Camera out = r.camera;
  if (r.accepted) {
    out.notes["refined_with_lines"] = image_path;
    out.notes["line_error_mean_mm"] = fmt::format("{:.1f}", r.after.mean_mm);
    out.notes["line_error_p95_mm"] = fmt::format("{:.1f}", r.after.p95_mm);
  }
  camera::WriteCameraYaml(out, c.out);
  std::cout << "wrote " << c.out << "\n";
  if (!c.overlay.empty()) WriteOverlay(c.overlay, out, image, field, c.o);
}

// ---- check
struct CheckCli {
  std::string camera, image, field, out, points, table;
  CheckOptions o;
};

void RunCheck(const CheckCli& c) {
  camera::Camera cam = camera::ReadCameraYaml(c.camera);
  const cv::Mat image = ReadImage(c.image);
  FitToImage(image, c.image, cam, fmt::format("camera file '{}'", c.camera));
  const field::FieldModel field = field::LoadField(c.field);
  std::vector<PointCorrespondence> pts;
  if (!c.points.empty()) pts = ReadPointsCsv(c.points, &field, cam.width, cam.height);
  const CheckResult r = CheckCalibration(cam, image, field, pts, c.o);
  if (!r.points.empty()) PrintPointTable(r.points);
  // No line pixel near a line: there is no line error to report (0.0 mm would read as perfect).
  FV_REQUIRE(r.lines.num_inliers > 0,
             "calibrate check: camera '{}' sees no line of field '{}' in '{}' ({} line pixels, "
             "none near a line): the pose or the field is wrong",
             c.camera, field.name, c.image, r.lines.num_pixels);
  std::cout << r.Summary() << "\n";
  std::cout << fmt::format("line error: mean {:.1f} mm, p95 {:.1f} mm\n", r.lines.mean_mm,
                           r.lines.p95_mm);
  io::WriteImage(c.out, r.overlay);
  std::cout << "wrote " << c.out << "\n";
  if (!c.table.empty()) {
    FV_REQUIRE(!r.points.empty(), "--table needs --points");
    WritePointErrorTable(c.table, r.points);
    std::cout << "wrote " << c.table << "\n";
  }
}

// ---- rig
struct RigCli {
  std::vector<std::string> cameras, points;
  std::string field, out_dir;
  RigOptions o;
};

void RunRig(const RigCli& c) {
  FV_REQUIRE(c.cameras.size() == c.points.size(),
             "{} --camera but {} --points; give one points file per camera", c.cameras.size(),
             c.points.size());
  const std::vector<std::string> paths = RigOutputPaths(
      c.cameras, c.out_dir, util::PathList(c.cameras, c.points, c.field), "--out-dir");
  std::unique_ptr<field::FieldModel> field;
  if (!c.field.empty()) field = std::make_unique<field::FieldModel>(field::LoadField(c.field));
  std::vector<camera::Camera> cams;
  std::vector<std::vector<RigObservation>> obs;
  for (size_t i = 0; i < c.cameras.size(); ++i) {
    cams.push_back(ReadNamedCamera(c.cameras[i]));
    obs.push_back(ReadRigObservations(c.points[i], field.get(), cams[i].width, cams[i].height));
  }
  const RigResult r = [&] {
    try {
      return RefineRig(cams, obs, c.o);
    } catch (const Error& e) {
      // "CAM has N observations; ...": name that camera's points file.
      const std::string what = e.what();
      for (size_t i = 0; i < cams.size(); ++i) {
        if (what.rfind(cams[i].name + " has ", 0) == 0) Throw("{}: {}", c.points[i], what);
      }
      throw;
    }
  }();
  std::cout << r.Summary() << "\n";
  if (r.free_points.empty()) {
    std::cout << "note: every point has a known position, so no point ties the cameras together: "
                 "each camera's pose was refined against its own points only (a robust fit from "
                 "the given poses; `calibrate extrinsics` instead starts afresh and leaves "
                 "outliers out by RANSAC); name points seen by several cameras without x,y,z to "
                 "adjust the rig jointly\n";
  }
  for (const auto& [name, p] : r.free_points) {
    std::cout << fmt::format("  point {}: ({:.3f}, {:.3f}, {:.3f}) m\n", name, p.x(), p.y(), p.z());
  }
  std::filesystem::create_directories(c.out_dir);
  for (size_t i = 0; i < r.cameras.size(); ++i) {
    const std::string& path = paths[i];
    camera::Camera out = r.cameras[i];
    out.notes["rig_rms_px"] = fmt::format("{:.3f}", r.reports[i].rms_after_px);
    camera::WriteCameraYaml(out, path);
    std::cout << "wrote " << path << "\n";
  }
}

// calibrate intrinsics
void SetupIntrinsics(CLI::App* group) {
  auto ic = std::make_shared<IntrinsicsCli>();
  CLI::App* in = group->add_subcommand(
      "intrinsics", "Intrinsics from chessboard or ChArUco views (a folder, a glob or a video)");
  in->add_option("--images", ic->images, "Folder, glob pattern ('dir/*.jpg') or video")->required();
  AddBoardOptions(in, ic->board);
  AddBoardFitOptions(in, ic->o);
  in->add_option("--k3", ic->k3,
                 "With --model 5, the r^6 term k3: auto (kept only on very strong evidence, BIC "
                 "gain over 10: a board that stays off the image's corners extrapolates k3 "
                 "there), free (OpenCV's) or zero; auto and free print how far apart the fits "
                 "with and without k3 put the image's corners and how each predicts the "
                 "outermost corners from the others")
      ->check(CLI::IsMember({"auto", "free", "zero"}))
      ->capture_default_str();
  in->add_flag("--fix-aspect", ic->o.fix_aspect_ratio, "Keep fx = fy");
  in->add_flag("--zero-tangent", ic->o.zero_tangent, "No tangential distortion");
  in->add_flag("--fix-principal-point", ic->o.fix_principal_point,
               "Principal point at the image centre");
  in->add_option("--subpix-window", ic->o.detect.subpix_half_window_px,
                 "cornerSubPix half window in pixels")
      ->check(FiniteRange(1, 50))
      ->capture_default_str();
  in->add_option("--subpix-cap", ic->o.detect.subpix_square_fraction,
                 "Cap the half window at this fraction of the smallest square (0: no cap, as "
                 "OpenCV's calibration sample)")
      ->check(FiniteRange(0, 1))
      ->capture_default_str();
  in->add_option("--name", ic->name, "Camera name written to the file");
  in->add_option("--out", ic->out, "Camera file to write (.yaml)")->required();
  in->add_flag("--quiet", ic->quiet, "No progress");
  in->callback([ic] {
    // Not one of the board images either (a folder or a glob lists them).
    std::vector<std::string> inputs = {ic->images};
    if (std::filesystem::is_directory(ic->images) ||
        ic->images.find_first_of("*?[") != std::string::npos) {
      const calib::ImageSource images(ic->images);
      for (int i = 0; i < images.size(); ++i) inputs.push_back(images.name(i));
    }
    util::CheckOutputPath(ic->out, inputs);
    CheckOutputFile(ic->out);
    RunIntrinsics(*ic);
  });
}

// calibrate extrinsics (a camera, a rig, or a phone with --image-size)
void SetupExtrinsics(CLI::App* group) {
  auto ec = std::make_shared<ExtrinsicsCli>();
  CLI::App* ex = group->add_subcommand(
      "extrinsics", "Camera pose from clicked points of known position (RANSAC PnP + refinement)");
  ex->add_option("--camera", ec->camera,
                 "Camera file with intrinsics (with --rig: the rig camera the --points belong to)");
  ex->add_option("--points", ec->points,
                 "CSV with u,v,x,y,z (metres) or u,v,name; with --rig NAME=POINTS.csv, repeated "
                 "for the rig's cameras")
      ->required();
  ex->add_option("--field", ec->field, "Field for named points (built-in name or JSON)");
  ex->add_option("--out", ec->out,
                 "Camera file to write (with --rig: a folder for every camera; with "
                 "--homography-only: the homography file)")
      ->required();
  ex->add_option("--rig", ec->rig,
                 "Folder of a calibrated rig (calibrate multi --out): place the whole rig from "
                 "points seen by any of its cameras, keeping their relative poses");
  ex->add_option("--image-size", ec->image_size,
                 "WxH: a camera without intrinsics (a phone); the focal length (principal point "
                 "at the centre) is estimated with the pose from 6 or more points, with its "
                 "uncertainty");
  ex->add_option("--image", ec->images,
                 "With --rig: NAME=FRAME (repeated) of the rig's cameras; after the points place "
                 "the rig, it is refined against the painted lines in these frames (--field "
                 "needed)");
  ex->add_flag("--k1", ec->k1, "With --image-size: also estimate the radial distortion k1");
  ex->add_flag("--homography-only", ec->homography_only,
               "With --image-size and ground points (z = 0): fit only the image-ground homography");
  ex->add_option("--threshold", ec->o.ransac_threshold_px, "RANSAC inlier threshold in pixels")
      ->check(FiniteRange(0.01, 1000))
      ->capture_default_str();
  ex->add_option("--table", ec->table, "Also write the per-point error table (CSV)");
  ex->callback([ec] {
    util::CheckOutputPath(ec->out,
                          util::PathList(ec->points, ec->field, ec->images));  // may be --camera
    util::CheckOutputPath(ec->table, util::PathList(ec->points, ec->field, ec->camera, ec->out),
                          "--table");
    if (ec->rig.empty()) CheckOutputFile(ec->out);
    CheckOutputFile(ec->table, "--table");
    RunExtrinsics(*ec);
  });
}

// calibrate refine (a camera or a rig)
void SetupRefine(CLI::App* group) {
  auto rc = std::make_shared<RefineCli>();
  CLI::App* re =
      group->add_subcommand("refine", "Refine the pose against the painted field lines in a frame");
  re->add_option("--camera", rc->camera,
                 "Camera file with a pose (with --rig: the rig camera of a plain --image)");
  re->add_option("--rig", rc->rig,
                 "Folder of a rig placed on the field: refine the whole rig (one rigid move, "
                 "relative poses kept) against the lines in the frames of any of its cameras "
                 "(--image NAME=FRAME, repeated); --out is then a folder");
  re->add_option("--image", rc->images,
                 "Frame of this camera (with --rig: NAME=FRAME, repeated for the rig's cameras)")
      ->required();
  re->add_option("--field", rc->field, "Field (built-in name or JSON)")->required();
  re->add_option("--out", rc->out, "Camera file to write (with --rig: a folder)")->required();
  re->add_option("--lut-resolution", rc->o.lut_resolution_m,
                 "Cell of the distance lookup table in metres")
      ->check(FiniteRange(1e-3, 0.5))
      ->capture_default_str();
  re->add_option("--overlay", rc->overlay,
                 "Also write the check image of the refined pose (with --rig: of the first "
                 "camera with a frame)");
  re->callback([rc] {
    std::vector<std::string> inputs = util::PathList(rc->field, FilesOf(rc->images));
    util::CheckOutputPath(rc->out, inputs);  // --out may be --camera
    inputs.push_back(rc->camera);
    inputs.push_back(rc->out);
    util::CheckOutputPath(rc->overlay, inputs, "--overlay");
    if (rc->rig.empty()) CheckOutputFile(rc->out);
    CheckOutputFile(rc->overlay, "--overlay");
    RunRefine(*rc);
  });
}

// calibrate check
void SetupCheck(CLI::App* group) {
  auto cc = std::make_shared<CheckCli>();
  CLI::App* ch = group->add_subcommand(
      "check", "Draw the field model over a frame and print the line error in mm");
  ch->add_option("--camera", cc->camera, "Camera file with a pose")->required();
  ch->add_option("--image", cc->image, "Frame of this camera")->required();
  ch->add_option("--field", cc->field, "Field (built-in name or JSON)")->required();
  ch->add_option("--out", cc->out, "Image to write (.png, .jpg)")->required();
  ch->add_option("--points", cc->points, "Known points (u,v,name or u,v,x,y,z) to tabulate");
  ch->add_option("--table", cc->table, "Write the known points' error table (CSV)");
  ch->callback([cc] {
    util::CheckOutputPath(cc->out, {cc->camera, cc->image, cc->field, cc->points});
    util::CheckOutputPath(cc->table, {cc->camera, cc->image, cc->field, cc->points, cc->out},
                          "--table");
    CheckOutputFile(cc->out);
    CheckOutputFile(cc->table, "--table");
    RunCheck(*cc);
  });
}

// calibrate rig
void SetupRig(CLI::App* group) {
  auto gc = std::make_shared<RigCli>();
  CLI::App* rg = group->add_subcommand(
      "rig", "Refine several cameras' poses jointly from shared observations (bundle adjustment)");
  rg->add_option("--camera", gc->cameras, "Camera file (repeat, one per camera)")->required();
  rg->add_option("--points", gc->points,
                 "Observations per camera: CSV u,v,name[,x,y,z] (repeat, in camera order)")
      ->required();
  rg->add_option("--field", gc->field, "Field whose keypoint names have known positions");
  rg->add_option("--out-dir", gc->out_dir, "Folder for the refined camera files")->required();
  rg->callback([gc] { RunRig(*gc); });
}

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "calibrate");
  SetupIntrinsics(group);
  SetupExtrinsics(group);
  SetupRefine(group);
  SetupCheck(group);
  SetupRig(group);
  (void)exit_code;
}

FV_REGISTER_COMMAND(20, "calibrate", Setup);

}  // namespace
}  // namespace fv::app
