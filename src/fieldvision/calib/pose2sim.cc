#include "fieldvision/calib/pose2sim.h"

#include <cmath>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <fmt/format.h>
#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::calib {
namespace {

// A tag's attributes (name="value"), read as numbers on lookup: a missing one or one that is not
// a finite number ("nan", "1,5") throws naming the file, the camera, the element and the value.
class Attributes {
 public:
  Attributes(const std::string& tag, std::string context) : context_(std::move(context)) {
    static const std::regex kAttr(R"((\w+)=\"([^\"]*)\")");
    for (auto it = std::sregex_iterator(tag.begin(), tag.end(), kAttr);
         it != std::sregex_iterator(); ++it) {
      values_[(*it)[1]] = (*it)[2];
    }
  }
  bool Has(const std::string& key) const { return values_.count(key) > 0; }
  double Number(const std::string& key) const {
    const auto it = values_.find(key);
    FV_REQUIRE(it != values_.end(), "{} has no {}", context_, key);
    const std::string where = fmt::format("{} {}", context_, key);
    const double v = util::ParseDouble(it->second, where);
    FV_REQUIRE(std::isfinite(v), "{}: '{}' is not a finite number", where, it->second);
    return v;
  }
  double NumberOr(const std::string& key, double fallback) const {
    return Has(key) ? Number(key) : fallback;
  }

 private:
  std::map<std::string, std::string> values_;
  std::string context_;
};

}  // namespace

std::vector<camera::Camera> ReadQualisysCalibration(const std::string& path,
                                                    std::vector<std::string>* skipped) {
  std::ifstream in(path);
  FV_REQUIRE(in.good(), "Qualisys calibration '{}' cannot be read", path);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  static const std::regex kCamera(
      R"(<camera [^>]*serial=\"([^\"]*)\"[\s\S]*?<fov_video ([^>]*)/>[\s\S]*?<transform ([^>]*)/>\s*<intrinsic ([^>]*)/>)");
  // A file cut short (a copy interrupted) would lose its last cameras without a word.
  FV_REQUIRE(text.find("</calibration>") != std::string::npos,
             "Qualisys calibration '{}' ends before '</calibration>' (truncated or not a .qca "
             "file)",
             path);
  std::vector<camera::Camera> cams;
  size_t left_out = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), kCamera);
       it != std::sregex_iterator(); ++it) {
    const std::string serial = (*it)[1].str();
    const auto element = [&](int group, const char* name) {
      return Attributes((*it)[group], fmt::format("Qualisys calibration '{}': camera {}'s {}", path,
                                                  serial, name));
    };
    const Attributes fov = element(2, "fov_video");
    const Attributes t = element(3, "transform");
    const Attributes k = element(4, "intrinsic");
    camera::Camera c;
    c.name = serial;
    if (fov.Number("right") == 0 && fov.Number("left") == 0 && fov.Number("bottom") == 0 &&
        fov.Number("top") == 0) {
      ++left_out;
      if (skipped != nullptr) {
        skipped->push_back(fmt::format(
            "camera {}: its fov_video is all zeros (not in the capture); left out", serial));
      }
      continue;
    }
    const double width = fov.Number("right") - fov.Number("left") + 1;
    const double height = fov.Number("bottom") - fov.Number("top") + 1;
    // 16 px a side at least (another size is a damaged element).
    FV_REQUIRE(width >= 16 && height >= 16 && width <= camera::Camera::kMaxSide &&
                   height <= camera::Camera::kMaxSide,
               "Qualisys calibration '{}': camera {}'s fov_video makes a {}x{} image", path, serial,
               width, height);
    c.width = static_cast<int>(width);
    c.height = static_cast<int>(height);
    c.fx = k.Number("focalLengthU") / 64.0;
    c.fy = k.Number("focalLengthV") / 64.0;
    c.cx = k.Number("centerPointU") / 64.0;
    c.cy = k.Number("centerPointV") / 64.0;
    c.distortion = {k.NumberOr("radialDistortion1", 0.0), k.NumberOr("radialDistortion2", 0.0),
                    k.NumberOr("tangentalDistortion1", 0.0),
                    k.NumberOr("tangentalDistortion2", 0.0)};
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r(i, j) = t.Number(fmt::format("r{}{}", i + 1, j + 1));
    }
    // A rotation: orthonormal, determinant +1 (a mistyped entry makes the camera's centre, R^T
    // times the position, land metres off).
    const double off_identity =
        (r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    FV_REQUIRE(off_identity < 1e-3,
               "Qualisys calibration '{}': camera {}'s transform r11..r33 is not a rotation "
               "(R R^T differs from the identity by {:.3g})",
               path, serial, off_identity);
    FV_REQUIRE(r.determinant() > 0,
               "Qualisys calibration '{}': camera {}'s transform r11..r33 mirrors (determinant "
               "{:.3g}): not a rotation",
               path, serial, r.determinant());
    const Eigen::Vector3d position_m(t.Number("x") / 1000, t.Number("y") / 1000,
                                     t.Number("z") / 1000);
    const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
    c.has_pose = true;
    c.cam_from_world.rotation = flip * r;
    c.cam_from_world.translation = -c.cam_from_world.rotation * position_m;
    c.Check("Qualisys calibration '" + path + "' camera " + c.name);
    cams.push_back(c);
  }
  FV_REQUIRE(!cams.empty(), "Qualisys calibration '{}' has no cameras{}", path,
             left_out > 0 ? " in the capture (every fov_video is all zeros)" : "");
  size_t tags = 0;
  for (size_t at = text.find("<camera "); at != std::string::npos;
       at = text.find("<camera ", at + 1)) {
    ++tags;
  }
  FV_REQUIRE(tags == cams.size() + left_out,
             "Qualisys calibration '{}': {} <camera> elements, {} of them whole (fov_video, "
             "transform and intrinsic each)",
             path, tags, cams.size() + left_out);
  return cams;
}

std::string RigComparison::Summary() const {
  std::string s = fmt::format(
      "baselines differ by at most {:.0f} mm, relative rotations by at most {:.2f} deg; camera "
      "centres after rigid alignment: rms {:.0f} mm",
      max_baseline_diff_mm, max_rotation_diff_deg, rms_aligned_err_mm);
  for (const auto& p : pairs) {
    s += fmt::format(
        "\n  cams {}-{}: baseline {:.0f} vs {:.0f} mm (diff {:+.0f} mm), relative "
        "rotation differs by {:.2f} deg",
        p.i + 1, p.j + 1, p.baseline_a_mm, p.baseline_b_mm, p.baseline_diff_mm,
        p.relative_rotation_diff_deg);
  }
  for (size_t i = 0; i < aligned_centre_err_mm.size(); ++i) {
    s += fmt::format("\n  cam {} centre off by {:.0f} mm after alignment", i + 1,
                     aligned_centre_err_mm[i]);
  }
  return s;
}

RigComparison CompareRigs(const std::vector<camera::Camera>& a,
                          const std::vector<camera::Camera>& b) {
  FV_REQUIRE(a.size() == b.size() && a.size() >= 2,
             "rig comparison needs two lists of the same cameras (got {} and {})", a.size(),
             b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    FV_REQUIRE(a[i].has_pose && b[i].has_pose, "rig comparison: camera {} has no pose", i + 1);
  }
  RigComparison out;
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = i + 1; j < a.size(); ++j) {
      RigComparison::Pair p;
      p.i = static_cast<int>(i);
      p.j = static_cast<int>(j);
      p.baseline_a_mm = 1000 * (a[i].CentreInWorld() - a[j].CentreInWorld()).norm();
      p.baseline_b_mm = 1000 * (b[i].CentreInWorld() - b[j].CentreInWorld()).norm();
      p.baseline_diff_mm = p.baseline_a_mm - p.baseline_b_mm;
      const Eigen::Matrix3d rel_a =
          a[i].cam_from_world.rotation * a[j].cam_from_world.rotation.transpose();
      const Eigen::Matrix3d rel_b =
          b[i].cam_from_world.rotation * b[j].cam_from_world.rotation.transpose();
      p.relative_rotation_diff_deg = geometry::RotationAngleBetween(rel_a, rel_b) * 180.0 / M_PI;
      out.max_baseline_diff_mm = std::max(out.max_baseline_diff_mm, std::abs(p.baseline_diff_mm));
      out.max_rotation_diff_deg = std::max(out.max_rotation_diff_deg, p.relative_rotation_diff_deg);
      out.pairs.push_back(p);
    }
  }
  Eigen::Matrix3Xd ca(3, a.size()), cb(3, b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ca.col(i) = a[i].CentreInWorld();
    cb.col(i) = b[i].CentreInWorld();
  }
  const Eigen::Matrix4d t = Eigen::umeyama(ca, cb, /*with_scaling=*/false);
  double sq = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector3d p = t.topLeftCorner<3, 3>() * ca.col(i) + t.topRightCorner<3, 1>();
    const double e = 1000 * (p - cb.col(i)).norm();
    out.aligned_centre_err_mm.push_back(e);
    sq += e * e;
  }
  out.rms_aligned_err_mm = std::sqrt(sq / a.size());
  return out;
}

}  // namespace fv::calib
