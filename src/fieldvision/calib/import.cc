#include "fieldvision/calib/import.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>
#include <opencv2/core.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::calib {
namespace {

// The camera tables under `table`, at any depth ([cam.1] is table 1 in table cam), named by their
// dotted path: those with a camera's key (a section without `matrix` is then an error naming
// the key, not a camera left out).
void CollectCameraTables(const toml::table& table, const std::string& prefix,
                         std::vector<std::pair<std::string, const toml::table*>>* out) {
  for (const auto& [key, node] : table) {
    const toml::table* t = node.as_table();
    if (t == nullptr) continue;
    const std::string name = prefix + std::string(key.str());
    if (t->contains("matrix") || t->contains("distortions") || t->contains("rotation") ||
        t->contains("translation")) {
      out->emplace_back(name, t);
    } else {
      CollectCameraTables(*t, name + ".", out);
    }
  }
}

// The camera tables of a calibration.toml in file order (toml::table orders its keys by name).
std::vector<std::pair<std::string, const toml::table*>> CameraSections(const toml::table& root) {
  std::vector<std::pair<std::string, const toml::table*>> out;
  CollectCameraTables(root, "", &out);
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return a.second->source().begin.line < b.second->source().begin.line;
  });
  return out;
}

toml::table ParseToml(const std::string& path) {
  FV_REQUIRE(std::ifstream(path).good() && !std::filesystem::is_directory(path),
             "calibration file '{}' cannot be read", path);
  try {
    return toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    Throw("{}:{}: {}", path, e.source().begin.line, e.description());
  }
}

// The numbers of an array, nested arrays flattened (a matrix as rows).
std::vector<double> Numbers(const toml::node* node, const std::string& where) {
  FV_REQUIRE(node != nullptr && node->is_array(), "{}: expected an array of numbers", where);
  std::vector<double> out;
  for (const toml::node& item : *node->as_array()) {
    if (item.is_array()) {
      const auto inner = Numbers(&item, where);
      out.insert(out.end(), inner.begin(), inner.end());
      continue;
    }
    const std::optional<double> v = item.value<double>();
    FV_REQUIRE(v.has_value() && (item.is_floating_point() || item.is_integer()),
               "{}: expected numbers", where);
    FV_REQUIRE(std::isfinite(*v), "{}: {} is not a finite number", where, *v);
    out.push_back(*v);
  }
  return out;
}

std::string Num(double v) { return fmt::format("{:.17g}", v); }

// A TOML basic string: quoted, with quotes, backslashes and control characters escaped.
std::string TomlString(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (u < 0x20 || u == 0x7f) {
      out += fmt::format("\\u{:04X}", u);
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

// A table name: bare when it is letters, digits, _ and - only, else quoted (a dot would nest it).
std::string TomlKey(const std::string& s) {
  const bool bare = !s.empty() && std::all_of(s.begin(), s.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
  });
  return bare ? s : TomlString(s);
}

cv::Mat ReadMat(const cv::FileStorage& fs, const std::string& key) {
  cv::Mat m;
  const cv::FileNode n = fs[key];
  if (!n.empty()) n >> m;
  if (!m.empty()) m.convertTo(m, CV_64F);
  return m;
}

}  // namespace

void ParseImageSize(const std::string& text, const std::string& what, int* width, int* height) {
  int w = 0, h = 0;
  char x = 0;
  std::istringstream is(text);
  FV_REQUIRE((is >> w >> x >> h) && (x == 'x' || x == 'X') && is.peek() == EOF && w > 0 && h > 0,
             "{} '{}' is not an image size like 1920x1080", what, text);
  FV_REQUIRE(w <= camera::Camera::kMaxSide && h <= camera::Camera::kMaxSide,
             "{} '{}' is over the limit of {} pixels a side", what, text, camera::Camera::kMaxSide);
  *width = w;
  *height = h;
}

std::vector<camera::Camera> ReadCalibrationToml(const std::string& path, double metres_per_unit) {
  CheckPositive(metres_per_unit, "metres_per_unit");
  const toml::table root = ParseToml(path);
  std::vector<camera::Camera> cams;
  for (const auto& [section, table_ptr] : CameraSections(root)) {
    const toml::table& table = *table_ptr;  // a plain reference: lambdas below capture it
    const std::string where = fmt::format("calibration file '{}' [{}]", path, section);
    auto get = [&](const char* key) {
      const toml::node* n = table.get(key);
      FV_REQUIRE(n != nullptr, "{}: key '{}' is missing", where, key);
      return n;
    };
    camera::Camera c;
    c.name = table["name"].value_or(section);
    const auto size = Numbers(get("size"), where + " size");
    FV_REQUIRE(size.size() == 2, "{}: size must be [width, height]", where);
    c.width = static_cast<int>(std::lround(size[0]));
    c.height = static_cast<int>(std::lround(size[1]));
    const auto k = Numbers(get("matrix"), where + " matrix");
    FV_REQUIRE(k.size() == 9, "{}: matrix must be 3x3 (got {} numbers)", where, k.size());
    c.fx = k[0];
    c.fy = k[4];
    c.cx = k[2];
    c.cy = k[5];
    FV_REQUIRE(std::abs(k[1]) < 1e-9 * std::abs(k[0]) + 1e-12,
               "{}: the matrix has a skew term {}; the OpenCV model has none", where, k[1]);
    FV_REQUIRE(!table["fisheye"].value_or(false),
               "{}: fisheye cameras are not supported (OpenCV's pinhole model only)", where);
    c.distortion = table.contains("distortions")
                       ? Numbers(table.get("distortions"), where + " distortions")
                       : std::vector<double>{};
    // k1 or k1 k2 alone: the radial terms, the rest 0 (three numbers could be k1 k2 k3 or k1 k2
    // p1: refused).
    if (c.distortion.size() == 1 || c.distortion.size() == 2) c.distortion.resize(4, 0.0);
    const size_t nd = c.distortion.size();
    FV_REQUIRE(nd == 0 || nd == 4 || nd == 5 || nd == 8 || nd == 12 || nd == 14,
               "{}: distortions has {} numbers; OpenCV's model takes 4, 5, 8, 12 or 14 (k1 k2 p1 "
               "p2 [k3 ...]), or k1 [k2] alone",
               where, nd);
    if (table.contains("rotation") && table.contains("translation")) {
      const auto r = Numbers(table.get("rotation"), where + " rotation");
      const auto t = Numbers(table.get("translation"), where + " translation");
      FV_REQUIRE(r.size() == 3 || r.size() == 9,
                 "{}: rotation must be a Rodrigues vector or a 3x3 matrix", where);
      FV_REQUIRE(t.size() == 3, "{}: translation must have 3 numbers", where);
      c.has_pose = true;
      if (r.size() == 3) {
        c.cam_from_world.rotation = geometry::RotationFromRvec({r[0], r[1], r[2]});
      } else {
        c.cam_from_world.rotation << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
      }
      c.cam_from_world.translation = Eigen::Vector3d(t[0], t[1], t[2]) * metres_per_unit;
    }
    c.notes["imported_from"] = path;
    c.Check(where);
    cams.push_back(c);
  }
  FV_REQUIRE(!cams.empty(),
             "calibration file '{}' has no camera sections (with 'matrix', 'distortions', "
             "'rotation', 'translation')",
             path);
  return cams;
}

void WriteCalibrationToml(const std::vector<camera::Camera>& cameras, const std::string& path) {
  FV_REQUIRE(!cameras.empty(), "no cameras to write to '{}'", path);
  std::set<std::string> names;
  for (size_t i = 0; i < cameras.size(); ++i) {
    const std::string name =
        cameras[i].name.empty() ? fmt::format("cam_{}", i + 1) : cameras[i].name;
    // A TOML file holds each table once: the second would make the file unreadable.
    FV_REQUIRE(names.insert(name).second,
               "two cameras are named '{}': calibration.toml holds each name once (set `name` in "
               "the camera files)",
               name);
  }
  util::AtomicWrite(
      path,
      [&](const std::string& tmp) {
        std::ofstream out(tmp);
        FV_REQUIRE(out.good(), "calibration file '{}' cannot be written", path);
        for (size_t i = 0; i < cameras.size(); ++i) {
          const camera::Camera& c = cameras[i];
          FV_REQUIRE(c.has_pose, "camera '{}' has no pose; calibration.toml needs one", c.name);
          const std::string name = c.name.empty() ? fmt::format("cam_{}", i + 1) : c.name;
          std::vector<double> d = c.distortion;
          d.resize(std::max<size_t>(d.size(), 4), 0.0);
          const Eigen::Vector3d r = c.cam_from_world.Rvec();
          const Eigen::Vector3d& t = c.cam_from_world.translation;
          out << "[" << TomlKey(name) << "]\n";
          out << "name = " << TomlString(name) << "\n";
          out << "size = [ " << c.width << ".0, " << c.height << ".0,]\n";
          out << "matrix = [ [ " << Num(c.fx) << ", 0.0, " << Num(c.cx) << ",], [ 0.0, "
              << Num(c.fy) << ", " << Num(c.cy) << ",], [ 0.0, 0.0, 1.0,],]\n";
          out << "distortions = [";
          for (size_t k = 0; k < d.size(); ++k) out << " " << Num(d[k]) << ",";
          out << "]\n";
          out << "rotation = [ " << Num(r.x()) << ", " << Num(r.y()) << ", " << Num(r.z())
              << ",]\n";
          out << "translation = [ " << Num(t.x()) << ", " << Num(t.y()) << ", " << Num(t.z())
              << ",]\n";
          out << "fisheye = false\n\n";
        }
        out << "[metadata]\nadjusted = false\nerror = 0.0\n";
        FV_REQUIRE(out.good(), "calibration file '{}' cannot be written", path);
      },
      "calibration file");
}

std::vector<camera::Camera> ReadOpenCvStereo(const std::vector<std::string>& paths, int width,
                                             int height, double metres_per_unit) {
  FV_REQUIRE(!paths.empty(), "no OpenCV stereo file given");
  FV_REQUIRE(width > 0 && height > 0, "OpenCV stereo files need the image size (--image-size)");
  CheckPositive(metres_per_unit, "metres_per_unit");
  cv::Mat m[2], d[2], r, t;
  for (const auto& p : paths) {
    FV_REQUIRE(std::filesystem::is_regular_file(p), "OpenCV stereo file '{}' does not exist", p);
    camera::CheckOpenCvYamlText(p, "OpenCV stereo file");
    cv::FileStorage fs;
    try {
      fs.open(p, cv::FileStorage::READ);
    } catch (const cv::Exception&) {
    }
    FV_REQUIRE(fs.isOpened(), "OpenCV stereo file '{}' cannot be read", p);
    for (int i = 0; i < 2; ++i) {
      const cv::Mat mi = ReadMat(fs, fmt::format("M{}", i + 1));
      const cv::Mat di = ReadMat(fs, fmt::format("D{}", i + 1));
      if (!mi.empty()) m[i] = mi;
      if (!di.empty()) d[i] = di;
    }
    const cv::Mat ri = ReadMat(fs, "R"), ti = ReadMat(fs, "T");
    if (!ri.empty()) r = ri;
    if (!ti.empty()) t = ti;
  }
  std::vector<camera::Camera> cams(2);
  for (int i = 0; i < 2; ++i) {
    FV_REQUIRE(!m[i].empty() && m[i].total() == 9, "OpenCV stereo files: no 3x3 M{} in {}", i + 1,
               paths.front());
    camera::Camera& c = cams[i];
    c.name = i == 0 ? "left" : "right";
    c.width = width;
    c.height = height;
    c.fx = m[i].at<double>(0, 0);
    c.fy = m[i].at<double>(1, 1);
    c.cx = m[i].at<double>(0, 2);
    c.cy = m[i].at<double>(1, 2);
    if (!d[i].empty()) c.distortion.assign(d[i].begin<double>(), d[i].end<double>());
    if (!c.distortion.empty() && c.distortion.size() < 4) c.distortion.resize(4, 0.0);
    if (c.distortion.size() > 5 && c.distortion.size() < 8) c.distortion.resize(8, 0.0);
  }
  if (!r.empty() || !t.empty()) {
    FV_REQUIRE(!r.empty() && !t.empty() && t.total() == 3 && (r.total() == 9 || r.total() == 3),
               "OpenCV stereo files: R and T must both be given (3x3 or 3x1, and 3x1)");
    Eigen::Matrix3d rot;
    if (r.total() == 9) {
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) rot(a, b) = r.at<double>(a, b);
      }
    } else {
      rot = geometry::RotationFromRvec({r.at<double>(0), r.at<double>(1), r.at<double>(2)});
    }
    cams[0].has_pose = true;
    cams[1].has_pose = true;
    cams[1].cam_from_world.rotation = rot;
    cams[1].cam_from_world.translation =
        Eigen::Vector3d(t.at<double>(0), t.at<double>(1), t.at<double>(2)) * metres_per_unit;
  }
  for (auto& c : cams) {
    c.notes["imported_from"] = paths.front();
    c.Check("OpenCV stereo camera " + c.name);
  }
  return cams;
}

}  // namespace fv::calib
