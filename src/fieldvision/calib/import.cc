#include "fieldvision/calib/import.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::calib {
namespace {

struct TomlValue {
  enum class Type { kString, kNumber, kBool, kArray } type = Type::kNumber;
  std::string text;
  double number = 0.0;
  bool boolean = false;
  std::vector<TomlValue> items;
};

class TomlParser {
 public:
  TomlParser(const std::string& s, const std::string& where) : s_(s), where_(where) {}
  TomlValue Value() {
    Skip();
    FV_REQUIRE(pos_ < s_.size(), "{}: a value is missing", where_);
    const char c = s_[pos_];
    TomlValue v;
    if (c == '[') {
      v.type = TomlValue::Type::kArray;
      ++pos_;
      while (true) {
        Skip();
        FV_REQUIRE(pos_ < s_.size(), "{}: an array is not closed", where_);
        if (s_[pos_] == ']') {
          ++pos_;
          break;
        }
        v.items.push_back(Value());
        Skip();
        if (pos_ < s_.size() && s_[pos_] == ',') ++pos_;
      }
      return v;
    }
    if (c == '"' || c == '\'') {
      v.type = TomlValue::Type::kString;
      const size_t end = s_.find(c, pos_ + 1);
      FV_REQUIRE(end != std::string::npos, "{}: a string is not closed", where_);
      v.text = s_.substr(pos_ + 1, end - pos_ - 1);
      pos_ = end + 1;
      return v;
    }
    size_t end = pos_;
    while (end < s_.size() && s_[end] != ',' && s_[end] != ']' &&
           !std::isspace(static_cast<unsigned char>(s_[end]))) {
      ++end;
    }
    const std::string tok = s_.substr(pos_, end - pos_);
    pos_ = end;
    if (tok == "true" || tok == "false") {
      v.type = TomlValue::Type::kBool;
      v.boolean = tok == "true";
      return v;
    }
    try {
      size_t used = 0;
      v.number = std::stod(tok, &used);
      FV_REQUIRE(used == tok.size(), "{}: '{}' is not a number", where_, tok);
    } catch (const std::logic_error&) {
      Throw("{}: '{}' is not a number, string, boolean or array", where_, tok);
    }
    return v;
  }

 private:
  void Skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  const std::string& s_;
  std::string where_;
  size_t pos_ = 0;
};

// Removes a # comment outside strings.
std::string StripComment(const std::string& line) {
  char quote = 0;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#') {
      return line.substr(0, i);
    }
  }
  return line;
}

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

using TomlTable = std::map<std::string, TomlValue>;

// Sections in file order, each a table of key -> value.
std::vector<std::pair<std::string, TomlTable>> ParseToml(const std::string& path) {
  std::ifstream in(path);
  FV_REQUIRE(in.good(), "calibration file '{}' cannot be read", path);
  util::SkipUtf8Bom(in);
  std::vector<std::pair<std::string, TomlTable>> out;
  out.emplace_back("", TomlTable{});
  std::string line, pending_key, pending;
  int depth = 0, line_no = 0, key_line = 0;
  while (std::getline(in, line)) {
    ++line_no;
    line = StripComment(line);
    if (!pending_key.empty()) {
      pending += "\n" + line;
    } else {
      const std::string t = Trim(line);
      if (t.empty()) continue;
      if (t.front() == '[' && t.find('=') == std::string::npos) {
        FV_REQUIRE(t.back() == ']', "{}:{}: a section header is not closed", path, line_no);
        out.emplace_back(Trim(t.substr(1, t.size() - 2)), TomlTable{});
        continue;
      }
      const size_t eq = t.find('=');
      FV_REQUIRE(eq != std::string::npos, "{}:{}: expected key = value", path, line_no);
      pending_key = Trim(t.substr(0, eq));
      pending = t.substr(eq + 1);
      key_line = line_no;
    }
    depth = 0;
    char quote = 0;
    for (char c : pending) {
      if (quote) {
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '[') {
        ++depth;
      } else if (c == ']') {
        --depth;
      }
    }
    if (depth > 0) continue;
    const std::string where = fmt::format("{}:{}: key '{}'", path, key_line, pending_key);
    TomlParser p(pending, where);
    out.back().second[pending_key] = p.Value();
    pending_key.clear();
    pending.clear();
  }
  FV_REQUIRE(pending_key.empty(), "{}:{}: the value of '{}' is not closed", path, key_line,
             pending_key);
  return out;
}

std::vector<double> Numbers(const TomlValue& v, const std::string& where) {
  FV_REQUIRE(v.type == TomlValue::Type::kArray, "{}: expected an array of numbers", where);
  std::vector<double> out;
  for (const auto& item : v.items) {
    if (item.type == TomlValue::Type::kArray) {
      const auto inner = Numbers(item, where);
      out.insert(out.end(), inner.begin(), inner.end());
    } else {
      FV_REQUIRE(item.type == TomlValue::Type::kNumber, "{}: expected numbers", where);
      FV_REQUIRE(std::isfinite(item.number), "{}: {} is not a finite number", where, item.number);
      out.push_back(item.number);
    }
  }
  return out;
}

std::string Num(double v) { return fmt::format("{:.17g}", v); }

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
  *width = w;
  *height = h;
}

std::vector<camera::Camera> ReadCalibrationToml(const std::string& path, double metres_per_unit) {
  CheckPositive(metres_per_unit, "metres_per_unit");
  const auto sections = ParseToml(path);
  std::vector<camera::Camera> cams;
  for (const auto& entry : sections) {
    const auto& section = entry.first;
    const auto& table = entry.second;  // a plain reference: lambdas below capture it
    if (!table.count("matrix")) continue;
    const std::string where = fmt::format("calibration file '{}' [{}]", path, section);
    auto get = [&](const char* key) -> const TomlValue& {
      const auto it = table.find(key);
      FV_REQUIRE(it != table.end(), "{}: key '{}' is missing", where, key);
      return it->second;
    };
    camera::Camera c;
    c.name = section;
    if (table.count("name") && table.at("name").type == TomlValue::Type::kString) {
      c.name = table.at("name").text;
    }
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
    if (table.count("fisheye")) {
      FV_REQUIRE(!table.at("fisheye").boolean,
                 "{}: fisheye cameras are not supported (OpenCV's pinhole model only)", where);
    }
    c.distortion = table.count("distortions")
                       ? Numbers(table.at("distortions"), where + " distortions")
                       : std::vector<double>{};
    // k1 or k1 k2 alone: the radial terms, the rest 0 (three numbers could be k1 k2 k3 or k1 k2
    // p1: refused).
    if (c.distortion.size() == 1 || c.distortion.size() == 2) c.distortion.resize(4, 0.0);
    const size_t nd = c.distortion.size();
    FV_REQUIRE(nd == 0 || nd == 4 || nd == 5 || nd == 8 || nd == 12 || nd == 14,
               "{}: distortions has {} numbers; OpenCV's model takes 4, 5, 8, 12 or 14 (k1 k2 p1 "
               "p2 [k3 ...]), or k1 [k2] alone",
               where, nd);
    if (table.count("rotation") && table.count("translation")) {
      const auto r = Numbers(table.at("rotation"), where + " rotation");
      const auto t = Numbers(table.at("translation"), where + " translation");
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
  FV_REQUIRE(!cams.empty(), "calibration file '{}' has no camera sections (with a 'matrix' key)",
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
          out << "[" << name << "]\n";
          out << "name = \"" << name << "\"\n";
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
