#include "fieldvision/camera/camera_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <opencv2/core.hpp>

#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/strings.h"

namespace fv::camera {
namespace {

cv::Mat ReadMatrix(const cv::FileNode& node, const std::string& path, const char* key) {
  // OpenCV allocates rows x cols before reading the data: a camera's matrices are small.
  FV_REQUIRE(node.isMap() && node["rows"].isInt() && node["cols"].isInt(),
             "camera file '{}': key '{}' is not a matrix (rows, cols, dt, data)", path, key);
  const int rows = static_cast<int>(node["rows"]), cols = static_cast<int>(node["cols"]);
  FV_REQUIRE(rows >= 1 && cols >= 1 && rows <= 16 && cols <= 16,
             "camera file '{}': key '{}' has {}x{} values (at most 16x16)", path, key, rows, cols);
  cv::Mat m;
  try {
    node >> m;
  } catch (const cv::Exception&) {
    Throw("camera file '{}': key '{}' is not a matrix", path, key);
  }
  FV_REQUIRE(!m.empty(), "camera file '{}': key '{}' is not a matrix", path, key);
  FV_REQUIRE(m.channels() == 1, "camera file '{}': key '{}' must have one channel", path, key);
  m.convertTo(m, CV_64F);
  for (int r = 0; r < m.rows; ++r) {
    for (int c = 0; c < m.cols; ++c) {
      FV_REQUIRE(std::isfinite(m.at<double>(r, c)),
                 "camera file '{}': key '{}' contains NaN or inf", path, key);
    }
  }
  return m;
}

int ReadPositiveInt(const cv::FileStorage& fs, const std::string& path, const char* key) {
  const cv::FileNode node = fs[key];
  FV_REQUIRE(!node.empty(), "camera file '{}': missing key '{}'", path, key);
  FV_REQUIRE(node.isInt(), "camera file '{}': key '{}' must be an integer", path, key);
  const int v = static_cast<int>(node);
  FV_REQUIRE(v > 0, "camera file '{}': key '{}' must be > 0 (got {})", path, key, v);
  return v;
}

Eigen::Vector3d ReadVector3(const cv::FileStorage& fs, const std::string& path, const char* key) {
  const cv::Mat m = ReadMatrix(fs[key], path, key);
  FV_REQUIRE(m.total() == 3 && (m.rows == 1 || m.cols == 1),
             "camera file '{}': key '{}' must be 3x1 (got {}x{})", path, key, m.rows, m.cols);
  return {m.at<double>(0), m.at<double>(1), m.at<double>(2)};
}

Camera ReadCameraYamlFrom(const cv::FileStorage& fs, const std::string& path) {
  Camera cam;
  cam.width = ReadPositiveInt(fs, path, "image_width");
  cam.height = ReadPositiveInt(fs, path, "image_height");

  FV_REQUIRE(!fs["camera_matrix"].empty(), "camera file '{}': missing key 'camera_matrix'", path);
  const cv::Mat k = ReadMatrix(fs["camera_matrix"], path, "camera_matrix");
  FV_REQUIRE(k.rows == 3 && k.cols == 3,
             "camera file '{}': key 'camera_matrix' must be 3x3 (got {}x{})", path, k.rows, k.cols);
  cam.fx = k.at<double>(0, 0);
  cam.fy = k.at<double>(1, 1);
  cam.cx = k.at<double>(0, 2);
  cam.cy = k.at<double>(1, 2);
  FV_REQUIRE(cam.fx > 0 && cam.fy > 0,
             "camera file '{}': key 'camera_matrix' has a non-positive focal length (fx={}, fy={})",
             path, cam.fx, cam.fy);
  FV_REQUIRE(k.at<double>(1, 0) == 0 && k.at<double>(2, 0) == 0 && k.at<double>(2, 1) == 0 &&
                 k.at<double>(2, 2) == 1,
             "camera file '{}': key 'camera_matrix' must have last row [0 0 1]", path);
  FV_REQUIRE(std::abs(k.at<double>(0, 1)) < 1e-9 * cam.fx,
             "camera file '{}': key 'camera_matrix' has a skew; OpenCV's model has none", path);

  if (!fs["distortion_coefficients"].empty()) {
    const cv::Mat d = ReadMatrix(fs["distortion_coefficients"], path, "distortion_coefficients");
    FV_REQUIRE(d.rows == 1 || d.cols == 1,
               "camera file '{}': key 'distortion_coefficients' must be 1xN", path);
    const size_t n = d.total();
    FV_REQUIRE(n == 4 || n == 5 || n == 8 || n == 12 || n == 14,
               "camera file '{}': key 'distortion_coefficients' has {} values; allowed 4, 5, 8, "
               "12, 14",
               path, n);
    cam.distortion.assign(d.begin<double>(), d.end<double>());
  } else {
    Throw("camera file '{}': missing key 'distortion_coefficients'", path);
  }

  const bool has_r = !fs["rvec"].empty();
  const bool has_t = !fs["tvec"].empty();
  FV_REQUIRE(has_r == has_t, "camera file '{}': key '{}' is present without '{}'", path,
             has_r ? "rvec" : "tvec", has_r ? "tvec" : "rvec");
  if (has_r) {
    cam.has_pose = true;
    cam.cam_from_world = geometry::Rigid3d::FromRvecTvec(ReadVector3(fs, path, "rvec"),
                                                         ReadVector3(fs, path, "tvec"));
  }
  if (fs["name"].isString()) cam.name = static_cast<std::string>(fs["name"]);
  if (fs["rms_px"].isReal() || fs["rms_px"].isInt()) {
    cam.rms_px = static_cast<double>(fs["rms_px"]);
  }
  const cv::FileNode notes = fs["notes"];
  if (notes.isMap()) {
    for (const auto& n : notes) {
      if (!n.isString()) continue;
      // Only names that OpenCV can write back (WriteCameraYaml) are kept as notes.
      const std::string key = n.name();
      const bool valid =
          !key.empty() && (std::isalpha(static_cast<unsigned char>(key[0])) || key[0] == '_') &&
          std::all_of(key.begin(), key.end(), [](char ch) {
            return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
          });
      FV_REQUIRE(valid, "camera file '{}': notes key '{}' is not a name (letters, digits, _ or -)",
                 path, key);
      cam.notes[key] = static_cast<std::string>(n);
    }
  }
  cam.Check("camera file '" + path + "'");
  return cam;
}

}  // namespace

void CheckOpenCvYamlText(const std::string& path, const std::string& what) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  FV_REQUIRE(!ec, "{} '{}' cannot be read: {}", what, path, ec.message());
  FV_REQUIRE(size <= (64u << 20), "{} '{}' is {} bytes: not a calibration file", what, path, size);
  std::ifstream in(path, std::ios::binary);
  FV_REQUIRE(in.good(), "{} '{}' cannot be read", what, path);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.rfind("---", 0) != 0) continue;
    const size_t rest = line.find_first_not_of(" \t\r", 3);
    FV_REQUIRE(rest == std::string::npos || line[rest] == '#',
               "{} '{}' line {}: '---' must stand alone on its line", what, path, n);
  }
}

Camera ReadCameraYaml(const std::string& path) {
  FV_REQUIRE(!std::filesystem::is_directory(path),
             "camera file '{}' is a folder (give one of its .yaml files)", path);
  FV_REQUIRE(std::filesystem::is_regular_file(path), "camera file '{}' does not exist", path);
  CheckOpenCvYamlText(path, "camera file");
  // Read as text, without a UTF-8 byte-order mark (Windows Notepad writes one; OpenCV's parser
  // refuses the file then).
  std::ifstream in(path, std::ios::binary);
  util::SkipUtf8Bom(in);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  cv::FileStorage fs;
  try {
    fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    FV_REQUIRE(fs.isOpened(), "camera file '{}' cannot be read as OpenCV YAML", path);
    FV_REQUIRE(fs.root().isMap(), "camera file '{}' is not a map of keys", path);
    return ReadCameraYamlFrom(fs, path);
  } catch (const Error&) {
    throw;
  } catch (const cv::Exception&) {
    // OpenCV's parser and FileNode accessors assert on malformed structure,
    Throw("camera file '{}' is not valid OpenCV YAML", path);
  } catch (const std::exception&) {
    // or throw std::length_error (a key of length -1 in "   : 5").
    Throw("camera file '{}' is not valid OpenCV YAML", path);
  }
}

cv::FileStorage NewYamlWriter() {
  return cv::FileStorage(
      ".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
}

void SaveYaml(cv::FileStorage& fs, const std::string& file, const std::string& path,
              const std::string& what) {
  const std::string text = fs.releaseAndGetString();
  std::ofstream out(file, std::ios::binary);
  out << text;
  out.close();
  FV_REQUIRE(!out.fail(), "cannot write {} '{}'", what, path);
}

void WriteCameraYaml(const Camera& camera, const std::string& path) {
  camera.Check("camera to write to '" + path + "'");
  util::AtomicWrite(
      path,
      [&](const std::string& tmp) {
        cv::FileStorage fs = NewYamlWriter();
        // cv::write, not <<: << takes strings that start with [ ] { } for structure marks.
        if (!camera.name.empty()) cv::write(fs, "name", camera.name);
        fs << "image_width" << camera.width << "image_height" << camera.height;
        fs << "camera_matrix" << cv::Mat(IntrinsicMatrix(camera));
        fs << "distortion_coefficients" << DistortionRow(camera);
        if (camera.has_pose) {
          const Eigen::Vector3d r = camera.cam_from_world.Rvec();
          const Eigen::Vector3d& t = camera.cam_from_world.translation;
          fs << "rvec" << (cv::Mat_<double>(3, 1) << r.x(), r.y(), r.z());
          fs << "tvec" << (cv::Mat_<double>(3, 1) << t.x(), t.y(), t.z());
          const Eigen::Vector3d c = camera.CentreInWorld();
          fs << "camera_position_m" << (cv::Mat_<double>(3, 1) << c.x(), c.y(), c.z());
        }
        if (camera.rms_px) fs << "rms_px" << *camera.rms_px;
        if (!camera.notes.empty()) {
          fs << "notes"
             << "{";
          for (const auto& [key, value] : camera.notes) cv::write(fs, key, value);
          fs << "}";
        }
        SaveYaml(fs, tmp, path, "camera file");
      },
      "camera file");
}

}  // namespace fv::camera
