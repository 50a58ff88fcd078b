// `fieldvision calibrate import` / `calibrate export`: calibrations made elsewhere as the camera
// files of CONTRACT.md (Tsai XML as PETS, Qualisys .qca.txt, Pose2Sim/anipose calibration.toml,
// OpenCV stereo YAML/XML), and camera files back to calibration.toml.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

#include <fmt/format.h>

#include "fieldvision/app/camera_folder.h"
#include "fieldvision/app/command.h"
#include "fieldvision/calib/import.h"
#include "fieldvision/calib/pose2sim.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/track/pets.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::app {
namespace {

struct ImportCli {
  std::string tsai, qualisys, toml, out, name, image_size, units = "m";
  std::vector<std::string> opencv_stereo;
};

struct ExportCli {
  std::vector<std::string> cameras;
  std::string rig, toml;
};

// The name attribute of a Tsai file's <Camera name="..."> ("" when absent).
std::string TsaiCameraName(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  static const std::regex kName(R"(<Camera[^>]*\sname\s*=\s*\"([^\"]*)\")");
  std::smatch m;
  return std::regex_search(text, m, kName) ? m[1].str() : std::string();
}

double MetresPerUnit(const std::string& units) {
  if (units == "m") return 1.0;
  if (units == "mm") return 0.001;
  if (units == "cm") return 0.01;
  Throw("--units '{}' is not known; use m, cm or mm", units);
}

// NAME.yaml per camera in `dir` (CameraFilePaths: safe names, none shared).
// `inputs`: the files read (none may be replaced).
void WriteCameras(const std::vector<camera::Camera>& cams, const std::string& dir,
                  const std::vector<std::string>& inputs) {
  const std::vector<std::string> paths = CameraFilePaths(cams, dir, "--out", inputs);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  FV_REQUIRE(std::filesystem::is_directory(dir), "cannot make folder --out '{}'", dir);
  for (size_t i = 0; i < cams.size(); ++i) {
    const std::string name = CameraNameOr(cams[i], i);
    const std::string& path = paths[i];
    camera::WriteCameraYaml(cams[i], path);
    const Eigen::Vector3d c = cams[i].has_pose ? cams[i].CentreInWorld() : Eigen::Vector3d::Zero();
    std::cout << fmt::format(
        "{}: {}x{}, fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}{}\nwrote {}\n", name, cams[i].width,
        cams[i].height, cams[i].fx, cams[i].fy, cams[i].cx, cams[i].cy,
        cams[i].has_pose ? fmt::format(", centre ({:.3f}, {:.3f}, {:.3f}) m", c.x(), c.y(), c.z())
                         : std::string(", no pose"),
        path);
  }
}

void RunImport(const ImportCli& c) {
  const int sources =
      !c.tsai.empty() + !c.qualisys.empty() + !c.toml.empty() + !c.opencv_stereo.empty();
  FV_REQUIRE(sources == 1, "give one of --tsai, --qualisys, --toml or --opencv-stereo (got {})",
             sources);
  FV_REQUIRE(c.image_size.empty() || !c.opencv_stereo.empty(),
             "--image-size goes with --opencv-stereo (the other files hold each camera's size)");
  if (!c.tsai.empty()) {
    const track::TsaiParameters p = track::ReadTsaiXml(c.tsai);
    std::string name = c.name;
    if (name.empty()) name = TsaiCameraName(c.tsai);
    if (name.empty()) name = std::filesystem::path(c.tsai).stem().string();
    const track::TsaiConversion conv = track::CameraFromTsai(p, name);
    util::CheckOutputPath(c.out, {c.tsai});
    // Tsai's one-coefficient radial model is fitted exactly by OpenCV's for real lenses (PETS
    // View_001: 0.000 px); a large difference is a distortion no lens has (a mistyped kappa1):
    // 50 pixels and more are not written (20 times PETS' kappa1, a very wide lens: 12 px).
    FV_REQUIRE(conv.max_fit_error_px <= 50.0,
               "'{}': OpenCV's lens model cannot follow Tsai's (up to {:.0f} px apart over the "
               "image): check kappa1 ({}) and the sensor sizes in the file; nothing written",
               c.tsai, conv.max_fit_error_px, p.kappa1);
    camera::WriteCameraYaml(conv.camera, c.out);
    std::cout << conv.Summary() << "\ncamera " << name << "\nwrote " << c.out << "\n";
    // Tx, Ty, Tz are millimetres: a camera within a metre of the world's origin had metres.
    if (const double from_origin_m = conv.camera.CentreInWorld().norm(); from_origin_m < 1.0) {
      std::cerr << fmt::format(
          "warning: '{}': the camera stands {:.3f} m from the world origin: Tsai files give Tx, "
          "Ty, Tz in millimetres (were they metres?)\n",
          c.tsai, from_origin_m);
    }
    if (conv.max_fit_error_px > 1.0) {
      std::cerr << fmt::format(
          "warning: '{}': OpenCV's lens model differs from Tsai's by up to {:.1f} px over the "
          "image: check kappa1 and the sensor sizes in the file\n",
          c.tsai, conv.max_fit_error_px);
    }
    return;
  }
  std::vector<camera::Camera> cams;
  if (!c.qualisys.empty()) {
    std::vector<std::string> skipped;
    cams = calib::ReadQualisysCalibration(c.qualisys, &skipped);
    for (const std::string& s : skipped)
      std::cerr << "warning: '" << c.qualisys << "': " << s << "\n";
  } else if (!c.toml.empty()) {
    cams = calib::ReadCalibrationToml(c.toml, MetresPerUnit(c.units));
  } else {
    int w = 0, h = 0;
    FV_REQUIRE(!c.image_size.empty(),
               "--opencv-stereo: the files do not hold the image size; give --image-size WxH");
    calib::ParseImageSize(c.image_size, "--image-size", &w, &h);
    cams = calib::ReadOpenCvStereo(c.opencv_stereo, w, h, MetresPerUnit(c.units));
  }
  if (!c.name.empty()) {
    FV_REQUIRE(cams.size() == 1, "--name applies to a single camera; the file has {}", cams.size());
    cams[0].name = c.name;
  }
  for (size_t i = 0; i + 1 < cams.size(); ++i) {
    if (!cams[i].has_pose || !cams[i + 1].has_pose) continue;
    const double baseline = (cams[i].CentreInWorld() - cams[i + 1].CentreInWorld()).norm();
    if (baseline > 100) {
      std::cerr << fmt::format(
          "warning: cameras {} and {} are {:.0f} m apart: were the translations in mm? (--units "
          "mm)\n",
          cams[i].name, cams[i + 1].name, baseline);
      break;
    }
  }
  WriteCameras(cams, c.out, util::PathList(c.qualisys, c.toml, c.opencv_stereo));
}

void RunExport(const ExportCli& c) {
  std::vector<std::string> files = c.cameras;
  if (!c.rig.empty()) {
    const std::vector<std::string> in_rig = CameraFilesIn(c.rig);
    files.insert(files.end(), in_rig.begin(), in_rig.end());
    std::sort(files.begin(), files.end());
  }
  FV_REQUIRE(c.rig.empty() || !files.empty(), "--rig '{}' holds no camera file (*.yaml)", c.rig);
  FV_REQUIRE(!files.empty(), "give --camera CAM.yaml (repeat) or --rig DIR");
  std::vector<camera::Camera> cams;
  cams.reserve(files.size());
  for (const auto& f : files) cams.push_back(ReadNamedCamera(f));
  util::CheckOutputPath(c.toml, files, "--toml");
  calib::WriteCalibrationToml(cams, c.toml);
  std::cout << "wrote " << c.toml << " (" << cams.size() << " cameras)\n";
}

// ---- compare
struct CompareCli {
  std::vector<std::string> rigs;
};

// Two calibrations of one rig compared without a common frame: per camera the intrinsics, per
// pair the baseline and relative rotation, and the centres after the best rigid alignment.
void RunCompare(const CompareCli& c) {
  FV_REQUIRE(c.rigs.size() == 2, "give --rig twice: the two calibrations to compare");
  const auto a_all = ReadCameraFolder(c.rigs[0]);
  const auto b_all = ReadCameraFolder(c.rigs[1]);
  std::vector<camera::Camera> a, b;
  for (const auto& ca : a_all) {
    for (const auto& cb : b_all) {
      if (cb.name != ca.name) continue;
      for (const auto& [cam, rig] : {std::pair{&ca, &c.rigs[0]}, {&cb, &c.rigs[1]}}) {
        FV_REQUIRE(cam->has_pose, "camera '{}' has no pose in rig '{}' (comparing needs poses)",
                   cam->name, *rig);
      }
      a.push_back(ca);
      b.push_back(cb);
    }
  }
  FV_REQUIRE(a.size() >= 2,
             "rigs '{}' and '{}' share {} camera names; comparing needs 2 or more (cameras are "
             "matched by their name or file name)",
             c.rigs[0], c.rigs[1], a.size());
  std::cout << fmt::format("{:<10s} {:>9s} {:>9s} {:>9s} {:>9s} {:>9s}\n", "camera", "fx_a", "fx_b",
                           "dfx_%", "dcx_px", "dcy_px");
  for (size_t i = 0; i < a.size(); ++i) {
    std::cout << fmt::format("{:<10s} {:>9.1f} {:>9.1f} {:>+9.2f} {:>+9.1f} {:>+9.1f}\n", a[i].name,
                             a[i].fx, b[i].fx, 100 * (a[i].fx - b[i].fx) / b[i].fx,
                             a[i].cx - b[i].cx, a[i].cy - b[i].cy);
  }
  const calib::RigComparison r = calib::CompareRigs(a, b);
  std::string names;
  for (size_t i = 0; i < a.size(); ++i) names += fmt::format(" {}={}", i + 1, a[i].name);
  std::cout << "cameras:" << names << "\n" << r.Summary() << "\n";
}

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "calibrate");
  auto c = std::make_shared<ImportCli>();
  CLI::App* cmd = group->add_subcommand(
      "import",
      "Import a calibration made elsewhere (Tsai XML, Qualisys, Pose2Sim/anipose TOML, OpenCV "
      "stereo)");
  cmd->add_option("--tsai", c->tsai, "Tsai camera file (e.g. PETS View_001.xml)");
  cmd->add_option("--qualisys", c->qualisys, "Qualisys calibration export (Calib.qca.txt)");
  cmd->add_option("--toml", c->toml, "Pose2Sim Calib.toml or anipose calibration.toml");
  cmd->add_option("--opencv-stereo", c->opencv_stereo,
                  "OpenCV stereo file(s) with M1 D1 M2 D2 [R T] (intrinsics.yml, extrinsics.yml; "
                  "repeat)");
  cmd->add_option("--image-size", c->image_size, "WxH, for --opencv-stereo");
  cmd->add_option("--units", c->units,
                  "Unit of the file's translations: m (Pose2Sim), mm or cm (anipose and OpenCV "
                  "use the board's unit)")
      ->capture_default_str();
  cmd->add_option("--out", c->out,
                  "Camera file to write (--tsai) or folder for NAME.yaml per camera (others)")
      ->required();
  cmd->add_option("--name", c->name,
                  "Camera name (default: the file's camera name, e.g. the Tsai name attribute)");
  cmd->callback([c, cmd] {
    // Tsai and Qualisys files say their unit (millimetres): --units would do nothing there.
    FV_REQUIRE(cmd->count("--units") == 0 || !c->toml.empty() || !c->opencv_stereo.empty(),
               "calibrate import: --units applies to --toml and --opencv-stereo only (Tsai and "
               "Qualisys files are in millimetres)");
    RunImport(*c);
  });

  auto e = std::make_shared<ExportCli>();
  CLI::App* ex = group->add_subcommand(
      "export", "Write camera files as a Pose2Sim / anipose calibration.toml (metres)");
  ex->add_option("--camera", e->cameras, "Camera file with a pose (repeat)");
  ex->add_option("--rig", e->rig, "Folder of camera files (e.g. calibrate multi --out)");
  ex->add_option("--toml", e->toml, "calibration.toml to write")->required();
  ex->callback([e] { RunExport(*e); });

  auto k = std::make_shared<CompareCli>();
  CLI::App* cm = group->add_subcommand(
      "compare",
      "Compare two calibrations of one rig without a common frame (intrinsics, baselines, "
      "relative rotations, centres after rigid alignment)");
  cm->add_option("--rig", k->rigs,
                 "Folder of camera files (give twice; cameras matched by name or file name)")
      ->required();
  cm->callback([k] { RunCompare(*k); });
  (void)exit_code;
}

FV_REGISTER_COMMAND(21, "calibrate import", Setup);

}  // namespace
}  // namespace fv::app
