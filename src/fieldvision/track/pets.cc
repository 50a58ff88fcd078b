#include "fieldvision/track/pets.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::track {
namespace {

std::string ReadAll(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  FV_REQUIRE(in.good(), "cannot open {} '{}'", what, path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Value of attribute `name` in an XML start tag `tag` ("" when absent).
std::string Attr(const std::string& tag, const std::string& name) {
  size_t pos = 0;
  while ((pos = tag.find(name, pos)) != std::string::npos) {
    const bool starts = pos > 0 && std::isspace(static_cast<unsigned char>(tag[pos - 1]));
    size_t eq = pos + name.size();
    while (eq < tag.size() && std::isspace(static_cast<unsigned char>(tag[eq]))) ++eq;
    if (starts && eq < tag.size() && tag[eq] == '=') {
      const size_t q = tag.find('"', eq);
      const size_t e = q == std::string::npos ? q : tag.find('"', q + 1);
      if (e != std::string::npos) return tag.substr(q + 1, e - q - 1);
    }
    pos += name.size();
  }
  return {};
}

double NumAttr(const std::string& tag, const std::string& name, const std::string& where) {
  const std::string v = Attr(tag, name);
  FV_REQUIRE(!v.empty(), "{}: attribute '{}' missing", where, name);
  return util::ParseDouble(v, where + " " + name);
}

// A frame number or id: a whole number in [0, 1e8] (NaN, 1e300 and 2e9 are refused).
int IndexAttr(const std::string& tag, const std::string& name, const std::string& where) {
  const double v = NumAttr(tag, name, where);
  FV_REQUIRE(v >= 0 && v <= 1e8 && v == std::floor(v),
             "{}: {} {} is not a whole number in [0, 1e8]", where, name, v);
  return static_cast<int>(v);
}

}  // namespace

std::vector<TrackRow> ReadPetsCvml(const std::string& path) {
  const std::string text = ReadAll(path, "PETS CVML annotation file");
  FV_REQUIRE(text.find("<dataset") != std::string::npos,
             "'{}' is not a CVML annotation file (no <dataset>)", path);
  std::vector<TrackRow> rows;
  std::set<std::pair<int, int>> boxed;  // (frame, id): one box each, as MOTChallenge allows
  int frame = -1, id = -1;
  size_t pos = 0;
  while ((pos = text.find('<', pos)) != std::string::npos) {
    const size_t end = text.find('>', pos);
    FV_REQUIRE(end != std::string::npos, "{}: unterminated tag at byte {}", path, pos);
    const std::string tag = text.substr(pos, end - pos + 1);
    pos = end + 1;
    const std::string where = fmt::format("{} (frame {})", path, frame);
    if (util::StartsWith(tag, "<frame ")) {
      frame = IndexAttr(tag, "number", where);
    } else if (util::StartsWith(tag, "<object ")) {
      id = IndexAttr(tag, "id", where);
    } else if (util::StartsWith(tag, "<box ")) {
      FV_REQUIRE(frame >= 0 && id >= 0, "{}: <box> outside a frame/object", where);
      const double xc = NumAttr(tag, "xc", where), yc = NumAttr(tag, "yc", where);
      const double w = NumAttr(tag, "w", where), h = NumAttr(tag, "h", where);
      FV_REQUIRE(
          std::abs(xc) <= 1e6 && std::abs(yc) <= 1e6 && w >= 0 && w <= 1e6 && h >= 0 && h <= 1e6,
          "{}: box xc={} yc={} w={} h={} is not a box in an image (within +-1e6 px)", where, xc, yc,
          w, h);
      FV_REQUIRE(boxed.emplace(frame, id).second,
                 "{}: object {} has a second box in frame {} (an id, or a frame number, given "
                 "twice)",
                 where, id, frame);
      TrackRow r;
      r.frame = frame + 1;  // CVML numbers frames from 0, MOTChallenge from 1
      r.id = id;
      r.box = cv::Rect2d(xc - 0.5 * w, yc - 0.5 * h, w, h);
      rows.push_back(r);
    }
  }
  FV_REQUIRE(!rows.empty(), "'{}' has no annotated boxes", path);
  return rows;
}

TsaiParameters ReadTsaiXml(const std::string& path) {
  const std::string text = ReadAll(path, "Tsai calibration file");
  auto tag_of = [&](const std::string& name) {
    const size_t a = text.find("<" + name);
    FV_REQUIRE(a != std::string::npos, "'{}' is not a Tsai calibration: <{}> missing", path, name);
    return text.substr(a, text.find('>', a) - a + 1);
  };
  const std::string g = tag_of("Geometry"), in = tag_of("Intrinsic"), ex = tag_of("Extrinsic");
  TsaiParameters p;
  const std::string w = path;
  p.width = static_cast<int>(NumAttr(g, "width", w));
  p.height = static_cast<int>(NumAttr(g, "height", w));
  p.ncx = NumAttr(g, "ncx", w);
  p.nfx = NumAttr(g, "nfx", w);
  p.dx = NumAttr(g, "dx", w);
  p.dy = NumAttr(g, "dy", w);
  p.dpx = NumAttr(g, "dpx", w);
  p.dpy = NumAttr(g, "dpy", w);
  p.focal_mm = NumAttr(in, "focal", w);
  p.kappa1 = NumAttr(in, "kappa1", w);
  p.cx = NumAttr(in, "cx", w);
  p.cy = NumAttr(in, "cy", w);
  p.sx = NumAttr(in, "sx", w);
  p.tx_mm = NumAttr(ex, "tx", w);
  p.ty_mm = NumAttr(ex, "ty", w);
  p.tz_mm = NumAttr(ex, "tz", w);
  p.rx = NumAttr(ex, "rx", w);
  p.ry = NumAttr(ex, "ry", w);
  p.rz = NumAttr(ex, "rz", w);
  FV_REQUIRE(p.width > 0 && p.height > 0, "{}: image size must be > 0", path);
  FV_REQUIRE(p.focal_mm > 0 && p.dpx > 0 && p.dpy > 0 && p.sx > 0,
             "{}: focal, dpx, dpy and sx must be > 0", path);
  return p;
}

namespace {

// Tsai's rotation R = Rz(rz) Ry(ry) Rx(rx) (cal_tran.c), x_cam = R x_world + T.
Eigen::Matrix3d TsaiRotation(const TsaiParameters& p) {
  return (Eigen::AngleAxisd(p.rz, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(p.ry, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(p.rx, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace

Eigen::Vector2d TsaiProject(const TsaiParameters& p, const Eigen::Vector3d& world_m) {
  const Eigen::Vector3d xc =
      TsaiRotation(p) * (world_m * 1000.0) + Eigen::Vector3d(p.tx_mm, p.ty_mm, p.tz_mm);
  const double xu = p.focal_mm * xc.x() / xc.z(), yu = p.focal_mm * xc.y() / xc.z();
  // Undistorted -> distorted: solve Xu = Xd (1 + k r_d^2) along the radius (Newton).
  const double ru = std::hypot(xu, yu);
  double rd = ru;
  for (int i = 0; i < 30 && ru > 0; ++i) {
    const double f = rd * (1 + p.kappa1 * rd * rd) - ru;
    const double df = 1 + 3 * p.kappa1 * rd * rd;
    rd -= f / df;
  }
  const double s = ru > 0 ? rd / ru : 1.0;
  const double xd = xu * s, yd = yu * s;
  return {xd * p.sx / p.dpx + p.cx, yd / p.dpy + p.cy};
}

std::string TsaiConversion::Summary() const {
  return fmt::format(
      "{}x{} fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}, k1 {:.5f} k2 {:.5f} k3 {:.5f}; "
      "camera at ({:.2f}, {:.2f}, {:.2f}) m; largest difference from Tsai's model "
      "{:.3f} px",
      camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy, camera.distortion[0],
      camera.distortion[1], camera.distortion[4], camera.CentreInWorld().x(),
      camera.CentreInWorld().y(), camera.CentreInWorld().z(), max_fit_error_px);
}

TsaiConversion CameraFromTsai(const TsaiParameters& p, const std::string& name) {
  camera::Camera cam;
  cam.name = name;
  cam.width = p.width;
  cam.height = p.height;
  // Pixel = Xd * sx / dpx + Cx with Xd in mm on the sensor; normalised distorted x_d = Xd / f.
  cam.fx = p.focal_mm * p.sx / p.dpx;
  cam.fy = p.focal_mm / p.dpy;
  cam.cx = p.cx;
  cam.cy = p.cy;
  // Fit x_d = x_u (1 + k1 r_u^2 + k2 r_u^4 + k3 r_u^6) (normalised) to Tsai's
  // x_u = x_d (1 + kappa1 f^2 r_d^2), sampling r_d up to the farthest image corner.
  const double kf2 = p.kappa1 * p.focal_mm * p.focal_mm;
  double rd_max = 0;
  for (double u : {-0.5, p.width - 0.5}) {
    for (double v : {-0.5, p.height - 0.5}) {
      rd_max = std::max(rd_max, std::hypot((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy));
    }
  }
  rd_max *= 1.05;
  constexpr int kSamples = 200;
  Eigen::MatrixXd a(kSamples, 3);
  Eigen::VectorXd b(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const double rd = rd_max * (i + 1) / kSamples;
    const double ru = rd * (1 + kf2 * rd * rd);
    const double r2 = ru * ru;
    a.row(i) << r2, r2 * r2, r2 * r2 * r2;
    b(i) = rd / ru - 1.0;
  }
  const Eigen::Vector3d k = a.colPivHouseholderQr().solve(b);
  cam.distortion = {k(0), k(1), 0.0, 0.0, k(2)};
  cam.has_pose = true;
  cam.cam_from_world.rotation = TsaiRotation(p);
  cam.cam_from_world.translation = Eigen::Vector3d(p.tx_mm, p.ty_mm, p.tz_mm) / 1000.0;
  cam.notes["source"] = "Tsai calibration (fieldvision calibrate import --tsai)";
  cam.Check(name.empty() ? "Tsai camera" : name);
  TsaiConversion out{cam, 0.0};
  // Compare both models over a grid of image points back-projected to the ground plane.
  for (int gy = 0; gy <= 10; ++gy) {
    for (int gx = 0; gx <= 10; ++gx) {
      const Eigen::Vector2d px(gx * (p.width - 1) / 10.0, gy * (p.height - 1) / 10.0);
      const auto ray = cam.RayFromPixel(px);
      if (!ray) continue;
      const auto g = geometry::IntersectHorizontalPlane(*ray, 0.0);
      if (!g) continue;
      const Eigen::Vector2d t = TsaiProject(p, *g);
      out.max_fit_error_px = std::max(out.max_fit_error_px, (t - px).norm());
    }
  }
  return out;
}

}  // namespace fv::track
