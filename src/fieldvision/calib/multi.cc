#include "fieldvision/calib/multi.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/calib/intrinsics.h"
#include "fieldvision/camera/opencv_camera.h"
#include "fieldvision/camera/projection.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/progress.h"
#include "fieldvision/util/stats.h"
#include "fieldvision/util/strings.h"

namespace fv::calib {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// The last run of digits in a file's stem, or in a video frame's "#N"; -1 when there is none.
long long LastNumber(const std::string& name) {
  const size_t hash = name.rfind('#');
  const std::string s = hash != std::string::npos ? name.substr(hash + 1)
                                                  : std::filesystem::path(name).stem().string();
  size_t end = s.size();
  while (end > 0 && !std::isdigit(static_cast<unsigned char>(s[end - 1]))) --end;
  if (end == 0) return -1;
  size_t begin = end;
  while (begin > 0 && std::isdigit(static_cast<unsigned char>(s[begin - 1]))) --begin;
  if (end - begin > 15) return -1;
  return std::stoll(s.substr(begin, end - begin));
}

// Board corner (board frame, metres) -> pixel of camera c through the board's pose in the
// reference frame (ref_from_board) and the camera's (cam_from_ref).
struct BoardCornerCost {
  BoardCornerCost(const cv::Point2f& uv, const cv::Point3f& p)
      : u(uv.x), v(uv.y), x(p.x), y(p.y), z(p.z) {}
  template <typename T>
  bool operator()(const T* intrinsics, const T* cam_r, const T* cam_t, const T* board_r,
                  const T* board_t, T* residual) const {
    const T p[3] = {T(x), T(y), T(z)};
    T p_ref[3];
    ceres::AngleAxisRotatePoint(board_r, p, p_ref);
    for (int k = 0; k < 3; ++k) p_ref[k] += board_t[k];
    T uv[2];
    if (!camera::ProjectWorldPoint(intrinsics, cam_r, cam_t, p_ref, uv)) return false;
    residual[0] = uv[0] - T(u);
    residual[1] = uv[1] - T(v);
    return true;
  }
  double u, v, x, y, z;
};

struct ViewPose {
  bool ok = false;
  geometry::Rigid3d cam_from_board;
  double rms_px = 0.0;
};

std::vector<cv::Point2f> ProjectBoard(const camera::Camera& cam,
                                      const geometry::Rigid3d& cam_from_board,
                                      const std::vector<cv::Point3f>& pts, bool* all_in_front) {
  std::vector<cv::Point2f> out;
  out.reserve(pts.size());
  *all_in_front = true;
  for (const auto& p : pts) {
    const auto uv = cam.ProjectFromCamera(cam_from_board * Eigen::Vector3d(p.x, p.y, p.z));
    if (!uv) {
      *all_in_front = false;
      out.emplace_back(-1e6f, -1e6f);
    } else {
      out.emplace_back(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
    }
  }
  return out;
}

double RmsBetween(const std::vector<cv::Point2f>& a, const std::vector<cv::Point2f>& b) {
  double sq = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double dx = a[i].x - b[i].x, dy = a[i].y - b[i].y;
    sq += dx * dx + dy * dy;
  }
  return a.empty() ? 0.0 : std::sqrt(sq / a.size());
}

// Board pose in one view with known intrinsics: IPPE (planar), then Levenberg-Marquardt.
ViewPose BoardPose(const camera::Camera& cam, const BoardView& view) {
  ViewPose out;
  if (view.image_points.size() < 4) return out;
  const cv::Mat k(camera::IntrinsicMatrix(cam));
  const cv::Mat d = camera::DistortionRow(cam);
  cv::Mat rvec, tvec;
  try {
    if (!cv::solvePnP(view.object_points, view.image_points, k, d, rvec, tvec, false,
                      cv::SOLVEPNP_IPPE)) {
      return out;
    }
    cv::solvePnP(view.object_points, view.image_points, k, d, rvec, tvec, true,
                 cv::SOLVEPNP_ITERATIVE);
  } catch (const cv::Exception&) {
    return out;
  }
  out.cam_from_board =
      geometry::Rigid3d::FromRvecTvec({rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2)},
                                      {tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)});
  bool in_front = true;
  const auto proj = ProjectBoard(cam, out.cam_from_board, view.object_points, &in_front);
  if (!in_front) return out;
  out.rms_px = RmsBetween(proj, view.image_points);
  out.ok = std::isfinite(out.rms_px);
  return out;
}

}  // namespace

CameraViews ParseCameraViews(const std::string& arg) {
  const size_t eq = arg.find('=');
  FV_REQUIRE(eq != std::string::npos && eq > 0 && eq + 1 < arg.size(),
             "--views '{}': give NAME=GLOB_OR_DIR_OR_VIDEO (e.g. left='data/left*.jpg')", arg);
  CameraViews v{arg.substr(0, eq), arg.substr(eq + 1)};
  FV_REQUIRE(v.name.find_first_of("/\\ ") == std::string::npos,
             "--views '{}': the camera name '{}' must not contain '/', '\\' or spaces (it names "
             "the file NAME.yaml)",
             arg, v.name);
  return v;
}

Pairing ParsePairing(const std::string& name) {
  const std::string n = util::ToLower(name);
  if (n == "auto") return Pairing::kAuto;
  if (n == "order") return Pairing::kOrder;
  if (n == "frame" || n == "frame-number") return Pairing::kFrameNumber;
  Throw("pairing '{}' is not known; use auto, order or frame", name);
}

void MultiOptions::Check() const {
  board.Check();
  detect.Check();
  source.Check();
  CheckDistortionModel(num_distortion);
  CheckPositive(loss_px, "loss_px");
  CheckPositive(outlier_factor, "outlier_factor");
  CheckNonNegative(outlier_min_px, "outlier_min_px");
  CheckInRange(max_drop_fraction, 0.0, 0.9, "max_drop_fraction");
  FV_REQUIRE(min_shared_views >= 1, "min_shared_views must be >= 1 (got {})", min_shared_views);
  FV_REQUIRE(min_views >= 2, "min_views must be >= 2 (got {})", min_views);
  FV_REQUIRE(max_iterations >= 1, "max_iterations must be >= 1 (got {})", max_iterations);
  for (const auto& [name, cam] : known_intrinsics) cam.Check("known intrinsics of " + name);
}

std::string MultiResult::Summary() const {
  std::string s = fmt::format(
      "{} cameras, {} moments with the board ({}), rms {:.3f} px over the used corners; {} "
      "adjustments, {} iterations, cost {:.4g} -> {:.4g}",
      cameras.size(), num_frames, pairing, rms_px, num_adjustments, iterations, initial_cost,
      final_cost);
  for (const auto& c : camera_reports) {
    const camera::Camera* cam = nullptr;
    for (const auto& k : cameras) {
      if (k.name == c.name) cam = &k;
    }
    s += fmt::format(
        "\n  camera {}: {} of {} views used ({} images), rms {:.3f} px (alone {:.3f} px)", c.name,
        c.num_used, c.num_found, c.num_images, c.rms_px, c.own_rms_px);
    if (c.own_k3_corner_shift_px > 0) {
      s += fmt::format("; alone with and without k3 the image corners lie {:.1f} px apart",
                       c.own_k3_corner_shift_px);
    }
    if (cam) {
      s += fmt::format("; fx {:.2f} fy {:.2f} cx {:.2f} cy {:.2f}", cam->fx, cam->fy, cam->cx,
                       cam->cy);
    }
    if (!c.model.empty()) s += "; distortion " + c.model;
    if (c.tree_parent >= 0) {
      s += fmt::format("; chained from {} ({} shared views)", camera_reports[c.tree_parent].name,
                       c.tree_shared_views);
    } else {
      s += "; reference frame";
    }
  }
  for (const auto& p : pairs) {
    s += fmt::format("\n  pair {}-{}: rotation {:.3f} deg, baseline {:.2f} mm, {} shared views",
                     camera_reports[p.i].name, camera_reports[p.j].name, p.rotation_deg,
                     1000 * p.baseline_m, p.shared_views);
    if (p.has_opencv) {
      s += fmt::format(
          "; OpenCV stereoCalibrate: rotation {:.3f} deg, baseline {:.2f} mm (rms {:.3f} px), "
          "rotations differ by {:.3f} deg, baselines by {:+.2f} %",
          p.opencv_rotation_deg, 1000 * p.opencv_baseline_m, p.opencv_rms_px,
          p.opencv_rotation_diff_deg,
          100 * (p.baseline_m - p.opencv_baseline_m) / p.opencv_baseline_m);
    }
  }
  for (const auto& v : views) {
    if (!v.used) {
      s += fmt::format("\n  dropped view {} of {}: {}", v.name, camera_reports[v.camera].name,
                       v.dropped_because);
    }
  }
  return s;
}

CameraDetections DetectCameraViews(const CameraViews& camera, const MultiOptions& options) {
  options.Check();
  const ImageSource source(camera.source, options.source);
  CameraDetections out;
  out.name = camera.name;
  out.source = camera.source;
  util::Progress progress(fmt::format("camera {}: detecting corners", camera.name), source.size(),
                          "images", options.progress);
  cv::Size first_size;
  for (int i = 0; i < source.size(); ++i) {
    const cv::Mat image = source.Read(i);
    if (i == 0) first_size = image.size();
    FV_REQUIRE(image.size() == first_size, "camera '{}': image '{}' is {}x{} but '{}' is {}x{}",
               camera.name, source.name(i), image.cols, image.rows, source.name(0),
               first_size.width, first_size.height);
    out.views.push_back(DetectBoard(image, options.board, options.detect, source.name(i)));
    out.frame_numbers.push_back(LastNumber(source.name(i)));
    progress.Update(i + 1);
  }
  progress.Finish();
  out.larger_board = LargerChessboardInViews(out.views, source, options.board);
  return out;
}

std::vector<MultiFrame> PairViews(const std::vector<CameraDetections>& cameras, Pairing pairing,
                                  std::string* how) {
  FV_REQUIRE(cameras.size() >= 2, "a rig needs at least 2 cameras (got {}); give --views twice",
             cameras.size());
  const size_t n = cameras.size();
  // Frame numbers usable when every view has one and they are unique per camera.
  auto numbered = [&](size_t c, std::string* why) {
    std::set<long long> seen;
    for (size_t i = 0; i < cameras[c].views.size(); ++i) {
      const long long f = cameras[c].frame_numbers[i];
      if (f < 0) {
        if (why) *why = fmt::format("image '{}' has no number", cameras[c].views[i].name);
        return false;
      }
      if (!seen.insert(f).second) {
        if (why) *why = fmt::format("two images are numbered {}", f);
        return false;
      }
    }
    return true;
  };
  auto by_frame = [&]() {
    std::map<long long, MultiFrame> frames;
    for (size_t c = 0; c < n; ++c) {
      for (size_t i = 0; i < cameras[c].views.size(); ++i) {
        const long long f = cameras[c].frame_numbers[i];
        MultiFrame& m = frames[f];
        if (m.views.empty()) {
          m.key = fmt::format("frame {}", f);
          m.views.resize(n);
        }
        m.views[c] = cameras[c].views[i];
      }
    }
    std::vector<MultiFrame> out;
    out.reserve(frames.size());
    for (auto& [f, m] : frames) out.push_back(std::move(m));
    return out;
  };
  auto by_order = [&]() {
    for (size_t c = 1; c < n; ++c) {
      FV_REQUIRE(cameras[c].views.size() == cameras[0].views.size(),
                 "views cannot be paired: camera '{}' has {} images but camera '{}' has {}; name "
                 "the images with frame numbers (left07.jpg, right07.jpg) or give each camera the "
                 "same moments",
                 cameras[c].name, cameras[c].views.size(), cameras[0].name,
                 cameras[0].views.size());
    }
    std::vector<MultiFrame> out(cameras[0].views.size());
    for (size_t i = 0; i < out.size(); ++i) {
      out[i].key = fmt::format("#{}", i + 1);
      out[i].views.resize(n);
      for (size_t c = 0; c < n; ++c) out[i].views[c] = cameras[c].views[i];
    }
    return out;
  };
  auto shared_moments = [&](const std::vector<MultiFrame>& frames) {
    int count = 0;
    for (const auto& f : frames) {
      int cams = 0;
      for (const auto& v : f.views) cams += v.name.empty() ? 0 : 1;
      count += cams >= 2 ? 1 : 0;
    }
    return count;
  };
  if (pairing == Pairing::kFrameNumber) {
    for (size_t c = 0; c < n; ++c) {
      std::string why;
      FV_REQUIRE(numbered(c, &why),
                 "views of camera '{}' cannot be paired by frame number: {}; use --pairing order",
                 cameras[c].name, why);
    }
    auto frames = by_frame();
    FV_REQUIRE(shared_moments(frames) > 0,
               "views cannot be paired: no frame number occurs in two cameras (camera '{}' numbers "
               "{}..); use --pairing order",
               cameras[0].name, cameras[0].frame_numbers.empty() ? 0 : cameras[0].frame_numbers[0]);
    if (how) *how = "paired by frame number";
    return frames;
  }
  if (pairing == Pairing::kAuto) {
    bool all = true;
    for (size_t c = 0; c < n; ++c) all = all && numbered(c, nullptr);
    if (all) {
      auto frames = by_frame();
      if (shared_moments(frames) > 0) {
        if (how) *how = "paired by frame number";
        return frames;
      }
      for (size_t c = 1; c < n; ++c) {
        FV_REQUIRE(
            cameras[c].views.size() == cameras[0].views.size(),
            "views cannot be paired: no frame number occurs in two cameras (camera '{}' "
            "numbers {}..{}, camera '{}' {}..{}) and their image counts differ; give the "
            "images of one moment the same number",
            cameras[0].name,
            *std::min_element(cameras[0].frame_numbers.begin(), cameras[0].frame_numbers.end()),
            *std::max_element(cameras[0].frame_numbers.begin(), cameras[0].frame_numbers.end()),
            cameras[c].name,
            *std::min_element(cameras[c].frame_numbers.begin(), cameras[c].frame_numbers.end()),
            *std::max_element(cameras[c].frame_numbers.begin(), cameras[c].frame_numbers.end()));
      }
    }
  }
  if (how) *how = "paired by sorted order";
  return by_order();
}

namespace {  // The stages of CalibrateMultiFromFrames.

constexpr int kP1 = 4 + 2, kP2 = 4 + 3, kK3 = 4 + 4;  // in the intrinsics block (OpenCV order)

void CheckFrames(const std::vector<std::string>& names, const std::vector<MultiFrame>& frames) {
  const int nc = static_cast<int>(names.size());
  FV_REQUIRE(nc >= 2, "a rig needs at least 2 cameras (got {})", nc);
  const std::set<std::string> unique(names.begin(), names.end());
  FV_REQUIRE(static_cast<int>(unique.size()) == nc,
             "two cameras have the same name; give each --views a different NAME");
  for (const auto& f : frames) {
    FV_REQUIRE(static_cast<int>(f.views.size()) == nc, "moment {} has {} views for {} cameras",
               f.key, f.views.size(), nc);
  }
}

// Each camera's intrinsics: the known ones, or its own calibrateCamera fit of its views.
std::vector<camera::Camera> InitialIntrinsics(const std::vector<std::string>& names,
                                              const std::vector<MultiFrame>& frames,
                                              const MultiOptions& options,
                                              std::vector<MultiCameraReport>* reports) {
  const int nc = static_cast<int>(names.size());
  std::vector<camera::Camera> cams(nc);
  reports->resize(nc);
  for (int c = 0; c < nc; ++c) {
    auto& rep = (*reports)[c];
    rep.name = names[c];
    std::vector<BoardView> found;
    for (const auto& f : frames) {
      if (f.views[c].name.empty()) continue;
      ++rep.num_images;
      if (!f.views[c].image_points.empty()) found.push_back(f.views[c]);
    }
    rep.num_found = static_cast<int>(found.size());
    FV_REQUIRE(!found.empty(),
               "camera '{}': no {} found in any of its {} images (check --cols/--rows{})", names[c],
               options.board.Describe(), rep.num_images,
               options.board.type == BoardType::kCharuco ? ", --dictionary and --marker" : "");
    const auto known = options.known_intrinsics.find(names[c]);
    if (known != options.known_intrinsics.end()) {
      cams[c] = known->second;
      FV_REQUIRE(cams[c].width == found[0].image_size.width &&
                     cams[c].height == found[0].image_size.height,
                 "camera '{}': the known intrinsics are for {}x{} images but its images are {}x{}",
                 names[c], cams[c].width, cams[c].height, found[0].image_size.width,
                 found[0].image_size.height);
      cams[c].has_pose = false;
      cams[c].rms_px.reset();
      cams[c].notes.clear();
      continue;
    }
    FV_REQUIRE(rep.num_found >= options.min_views,
               "camera '{}': the {} was found in only {} of its {} images; its intrinsics need at "
               "least {} views (add views, or give its intrinsics with --intrinsics {}=CAM.yaml)",
               names[c], options.board.Describe(), rep.num_found, rep.num_images, options.min_views,
               names[c]);
    IntrinsicsOptions io;
    io.board = options.board;
    io.detect = options.detect;
    io.num_distortion = options.num_distortion;
    io.zero_tangent = options.tangential == TangentialModel::kZero;
    io.k3 = options.k3;
    io.min_views = options.min_views;
    io.progress = false;
    io.camera_name = names[c];
    try {
      const IntrinsicsResult ir = CalibrateFromViews(found, io);
      cams[c] = ir.camera;
      rep.own_rms_px = ir.rms_px;
      rep.own_k3_corner_shift_px = ir.k3_tested ? ir.k3_corner_shift_px : 0.0;
    } catch (const Error& e) {
      Throw("camera '{}': {}", names[c], e.what());
    }
    cams[c].notes.clear();
  }
  return cams;
}

using PoseGrid = std::vector<std::vector<ViewPose>>;  // [camera][frame]

PoseGrid BoardPoses(const std::vector<camera::Camera>& cams,
                    const std::vector<MultiFrame>& frames) {
  PoseGrid pose(cams.size(), std::vector<ViewPose>(frames.size()));
  for (size_t c = 0; c < cams.size(); ++c) {
    for (size_t f = 0; f < frames.size(); ++f) {
      const BoardView& v = frames[f].views[c];
      if (!v.image_points.empty()) pose[c][f] = BoardPose(cams[c], v);
    }
  }
  return pose;
}

struct Edge {
  int shared = 0;
  geometry::Rigid3d b_from_a;
};

// The relative pose of cameras a and b: of the candidates their shared views give, the one that
// best transfers the board from a to b in all shared views.
Edge RelativePose(int a, int b, const std::vector<camera::Camera>& cams,
                  const std::vector<MultiFrame>& frames, const PoseGrid& pose) {
  Edge e;
  std::vector<int> shared;
  for (size_t f = 0; f < frames.size(); ++f) {
    if (pose[a][f].ok && pose[b][f].ok) shared.push_back(static_cast<int>(f));
  }
  e.shared = static_cast<int>(shared.size());
  double best = 1e300;
  for (int f : shared) {
    const geometry::Rigid3d cand = pose[b][f].cam_from_board * pose[a][f].cam_from_board.Inverse();
    double score = 0;
    for (int g : shared) {
      bool in_front = true;
      const auto proj = ProjectBoard(cams[b], cand * pose[a][g].cam_from_board,
                                     frames[g].views[b].object_points, &in_front);
      score += in_front ? std::min(RmsBetween(proj, frames[g].views[b].image_points), 50.0) : 50.0;
    }
    if (score < best) {
      best = score;
      e.b_from_a = cand;
    }
  }
  return e;
}

// Camera poses in the first camera's frame, chained through a maximum spanning tree (Prim) of
// shared-view counts. Throws naming a camera that shares too few views with the others.
std::vector<geometry::Rigid3d> ChainCameras(const std::vector<std::string>& names,
                                            const std::vector<MultiFrame>& frames,
                                            const std::vector<camera::Camera>& cams,
                                            const PoseGrid& pose, const MultiOptions& options,
                                            std::vector<MultiCameraReport>* reports) {
  const int nc = static_cast<int>(names.size());
  std::vector<std::vector<Edge>> edges(nc, std::vector<Edge>(nc));
  for (int a = 0; a < nc; ++a) {
    for (int b = 0; b < nc; ++b) {
      if (a != b) edges[a][b] = RelativePose(a, b, cams, frames, pose);
    }
  }
  std::vector<bool> in_tree(nc, false);
  std::vector<geometry::Rigid3d> cam_from_ref(nc);
  in_tree[0] = true;
  for (int added = 1; added < nc; ++added) {
    int best_a = -1, best_b = -1, best_shared = 0;
    for (int a = 0; a < nc; ++a) {
      for (int b = 0; in_tree[a] && b < nc; ++b) {
        if (in_tree[b] || edges[a][b].shared < options.min_shared_views) continue;
        if (edges[a][b].shared > best_shared) {
          best_shared = edges[a][b].shared;
          best_a = a;
          best_b = b;
        }
      }
    }
    for (int b = 0; best_b < 0 && b < nc; ++b) {
      if (in_tree[b]) continue;
      std::string counts;
      for (int a = 0; a < nc; ++a) {
        if (a != b) {
          counts +=
              fmt::format("{}{} {}", counts.empty() ? "" : ", ", names[a], edges[a][b].shared);
        }
      }
      Throw(
          "camera '{}' never sees the board together with the rest of the rig (views shared "
          "with: {}; {} needed): add moments where '{}' and another camera both see the whole "
          "board, or check that the views pair up (--pairing)",
          names[b], counts, options.min_shared_views, names[b]);
    }
    in_tree[best_b] = true;
    cam_from_ref[best_b] = edges[best_a][best_b].b_from_a * cam_from_ref[best_a];
    (*reports)[best_b].tree_parent = best_a;
    (*reports)[best_b].tree_shared_views = best_shared;
  }
  return cam_from_ref;
}

// The bundle adjustment's parameters and the views it uses.
struct RigState {
  std::vector<std::array<double, camera::kNumIntrinsics>> intr;
  std::vector<int> num_distortion;
  std::vector<bool> fixed;                        // intrinsics kept constant
  std::vector<bool> tangential;                   // p1 p2 free (else zero)
  std::vector<bool> k3;                           // k3 free (else zero; 5+ coefficients)
  std::vector<Eigen::Vector3d> cam_r, cam_t;      // cam_from_ref
  std::vector<Eigen::Vector3d> board_r, board_t;  // ref_from_board per moment
  std::vector<bool> board_ok;
  std::vector<std::vector<bool>> used;  // [camera][frame]
  std::vector<std::vector<std::string>> dropped_because;
  int nc() const { return static_cast<int>(intr.size()); }
  int nf() const { return static_cast<int>(board_ok.size()); }
  int NumUsedViews() const {
    int n = 0;
    for (const auto& row : used) n += static_cast<int>(std::count(row.begin(), row.end(), true));
    return n;
  }
};

// The start of the adjustment: each board placed from the camera that sees it best.
RigState StartState(const std::vector<std::string>& names, const std::vector<MultiFrame>& frames,
                    const std::vector<camera::Camera>& cams,
                    const std::vector<geometry::Rigid3d>& cam_from_ref, const PoseGrid& pose,
                    const MultiOptions& options) {
  const int nc = static_cast<int>(cams.size()), nf = static_cast<int>(frames.size());
  RigState s;
  s.intr.resize(nc);
  s.cam_r.resize(nc);
  s.cam_t.resize(nc);
  for (int c = 0; c < nc; ++c) {
    s.intr[c] = cams[c].IntrinsicsBlock();
    s.num_distortion.push_back(static_cast<int>(cams[c].distortion.size()));
    s.fixed.push_back(!options.refine_intrinsics || options.known_intrinsics.count(names[c]) > 0);
    s.tangential.push_back(s.fixed[c] || options.tangential == TangentialModel::kFree);
    if (!s.tangential[c]) s.intr[c][kP1] = s.intr[c][kP2] = 0.0;
    // The choice is made with 5 coefficients, as for one camera; other models keep k3.
    s.k3.push_back(s.num_distortion[c] >= 5 &&
                   (s.fixed[c] || options.k3 == K3Model::kFree || s.num_distortion[c] != 5));
    if (s.num_distortion[c] >= 5 && !s.k3[c]) s.intr[c][kK3] = 0.0;
    s.cam_r[c] = cam_from_ref[c].Rvec();
    s.cam_t[c] = cam_from_ref[c].translation;
  }
  s.board_r.resize(nf);
  s.board_t.resize(nf);
  s.board_ok.assign(nf, false);
  for (int f = 0; f < nf; ++f) {
    int best = -1;
    for (int c = 0; c < nc; ++c) {
      if (pose[c][f].ok && (best < 0 || pose[c][f].rms_px < pose[best][f].rms_px)) best = c;
    }
    if (best < 0) continue;
    const geometry::Rigid3d ref_from_board =
        cam_from_ref[best].Inverse() * pose[best][f].cam_from_board;
    s.board_r[f] = ref_from_board.Rvec();
    s.board_t[f] = ref_from_board.translation;
    s.board_ok[f] = true;
  }
  s.used.assign(nc, std::vector<bool>(nf, false));
  s.dropped_because.assign(nc, std::vector<std::string>(nf));
  for (int c = 0; c < nc; ++c) {
    for (int f = 0; f < nf; ++f) {
      s.used[c][f] = s.board_ok[f] && !frames[f].views[c].image_points.empty();
    }
  }
  return s;
}

// Per-corner reprojection error of camera c's view of moment f.
std::vector<float> ViewErrors(const RigState& s, const std::vector<MultiFrame>& frames, int c,
                              int f) {
  const BoardView& v = frames[f].views[c];
  std::vector<float> err(v.image_points.size(), 1e6f);
  for (size_t k = 0; k < v.image_points.size(); ++k) {
    const BoardCornerCost cost(v.image_points[k], v.object_points[k]);
    double res[2];
    if (cost(s.intr[c].data(), s.cam_r[c].data(), s.cam_t[c].data(), s.board_r[f].data(),
             s.board_t[f].data(), res)) {
      err[k] = static_cast<float>(std::hypot(res[0], res[1]));
    }
  }
  return err;
}

double RmsOf(const std::vector<float>& err) {
  double sq = 0;
  for (float e : err) sq += static_cast<double>(e) * e;
  return err.empty() ? 0.0 : std::sqrt(sq / err.size());
}

// Sum of squared corner errors (px^2) over camera c's used views; *num_residuals: 2 per corner.
double CameraSse(const RigState& s, const std::vector<MultiFrame>& frames, int c,
                 long long* num_residuals) {
  double sq = 0;
  *num_residuals = 0;
  for (int f = 0; f < s.nf(); ++f) {
    if (!s.used[c][f]) continue;
    for (float e : ViewErrors(s, frames, c, f)) sq += static_cast<double>(e) * e;
    *num_residuals += 2 * static_cast<long long>(frames[f].views[c].image_points.size());
  }
  return sq;
}

// One Ceres solve of every used view (Huber loss), the first camera's pose fixed.
void SolveRig(RigState* s, const std::vector<MultiFrame>& frames, const MultiOptions& options,
              MultiResult* result) {
  ceres::Problem problem;
  for (int c = 0; c < s->nc(); ++c) {
    for (int f = 0; f < s->nf(); ++f) {
      if (!s->used[c][f]) continue;
      const BoardView& v = frames[f].views[c];
      for (size_t k = 0; k < v.image_points.size(); ++k) {
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<BoardCornerCost, 2, camera::kNumIntrinsics, 3, 3, 3, 3>(
                new BoardCornerCost(v.image_points[k], v.object_points[k])),
            new ceres::HuberLoss(options.loss_px), s->intr[c].data(), s->cam_r[c].data(),
            s->cam_t[c].data(), s->board_r[f].data(), s->board_t[f].data());
      }
    }
  }
  for (int c = 0; c < s->nc(); ++c) {
    if (!problem.HasParameterBlock(s->intr[c].data())) continue;
    if (s->fixed[c]) {
      problem.SetParameterBlockConstant(s->intr[c].data());
      continue;
    }
    std::vector<int> constant;
    if (!s->tangential[c]) constant = {kP1, kP2};
    if (s->num_distortion[c] >= 5 && !s->k3[c]) constant.push_back(kK3);
    for (int i = 4 + s->num_distortion[c]; i < camera::kNumIntrinsics; ++i) constant.push_back(i);
    if (!constant.empty()) {
      problem.SetManifold(s->intr[c].data(),
                          new ceres::SubsetManifold(camera::kNumIntrinsics, constant));
    }
  }
  if (problem.HasParameterBlock(s->cam_r[0].data())) {
    problem.SetParameterBlockConstant(s->cam_r[0].data());
    problem.SetParameterBlockConstant(s->cam_t[0].data());
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_SCHUR;
  so.max_num_iterations = options.max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.function_tolerance = 1e-10;
  so.parameter_tolerance = 1e-10;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  FV_REQUIRE(summary.IsSolutionUsable(), "the rig's bundle adjustment failed: {}", summary.message);
  if (result->num_adjustments == 0) result->initial_cost = summary.initial_cost;
  ++result->num_adjustments;
  result->iterations += static_cast<int>(summary.iterations.size());
  result->final_cost = summary.final_cost;
}

// Drops the worst views above the threshold (outlier_factor x median view RMS, outlier_min_px),
// keeping every camera calibrated and linked; at most max_drop in all. Returns how many now.
int DropOutlierViews(RigState* s, const std::vector<MultiFrame>& frames,
                     const MultiOptions& options, int max_drop, int* dropped_total) {
  std::vector<double> rms_all;
  std::vector<std::tuple<double, int, int>> candidates;
  for (int c = 0; c < s->nc(); ++c) {
    for (int f = 0; f < s->nf(); ++f) {
      if (!s->used[c][f]) continue;
      const double r = RmsOf(ViewErrors(*s, frames, c, f));
      rms_all.push_back(r);
      candidates.emplace_back(r, c, f);
    }
  }
  const double med = util::Median(rms_all);
  const double threshold = std::max(options.outlier_factor * med, options.outlier_min_px);
  std::sort(candidates.rbegin(), candidates.rend());
  int dropped_now = 0;
  for (const auto& [r, c, f] : candidates) {
    if (r <= threshold || *dropped_total >= max_drop) break;
    int views_left = 0, shared_left = 0;
    for (int g = 0; g < s->nf(); ++g) {
      if (!s->used[c][g] || g == f) continue;
      ++views_left;
      for (int o = 0; o < s->nc(); ++o) {
        if (o != c && s->used[o][g]) {
          ++shared_left;
          break;
        }
      }
    }
    if (views_left < options.min_views || shared_left < 1) continue;
    s->used[c][f] = false;
    s->dropped_because[c][f] =
        fmt::format("view RMS {:.2f} px > {:.2f} px ({:.1f} x median {:.2f})", r, threshold,
                    options.outlier_factor, med);
    ++*dropped_total;
    ++dropped_now;
  }
  return dropped_now;
}

// Bundle adjustments alternating with outlier-view drops, at most 4 rounds.
void AdjustRig(RigState* s, const std::vector<MultiFrame>& frames, const MultiOptions& options,
               int max_drop, int* dropped_total, MultiResult* result) {
  for (int round = 0; round < 4; ++round) {
    SolveRig(s, frames, options, result);
    if (DropOutlierViews(s, frames, options, max_drop, dropped_total) == 0) break;
  }
}

std::string ModelName(int num_distortion, bool tangential, bool k3) {
  static const char* const kNames[] = {"k1", "k2", "p1", "p2", "k3", "k4",   "k5",
                                       "k6", "s1", "s2", "s3", "s4", "tauX", "tauY"};
  std::string s;
  for (int i = 0; i < num_distortion; ++i) {
    if (!tangential && (i == 2 || i == 3)) continue;
    if (!k3 && i == 4) continue;
    s += fmt::format("{}{}", s.empty() ? "" : " ", kNames[i]);
  }
  return s;
}

double RigSse(const RigState& s, const std::vector<MultiFrame>& frames, long long* num_residuals) {
  double sse = 0;
  *num_residuals = 0;
  for (int c = 0; c < s.nc(); ++c) {
    long long n = 0;
    sse += CameraSse(s, frames, c, &n);
    *num_residuals += n;
  }
  return sse;
}

// An optional term of one camera's lens under automatic choice: p1 p2 (2 parameters) or k3 (1).
struct TermChoice {
  int camera = 0;
  bool k3 = false;  // else p1 p2
};

// The terms still to choose: cameras not fixed, under --tangential auto / --k3 auto.
std::vector<TermChoice> OpenTerms(const RigState& s, const MultiOptions& options) {
  std::vector<TermChoice> open;
  for (int c = 0; c < s.nc(); ++c) {
    if (s.fixed[c]) continue;
    if (options.tangential == TangentialModel::kAuto && !s.tangential[c]) {
      open.push_back({c, false});
    }
    if (options.k3 == K3Model::kAuto && s.num_distortion[c] == 5 && !s.k3[c]) {
      open.push_back({c, true});
    }
  }
  return open;
}

// The automatic choices, from the rig fitted without the open terms (*s): forward selection. Each
// open term is tried (the whole rig fitted again); the one with the largest BIC gain
// (util::BicGain on the rig's squared error, for its 2 or 1 parameters) is kept if it pays (k3:
// over kK3MinBicGain, very strong evidence, as for one camera), and the others are tried again
// given it. One camera's lens error moves the shared board poses and so every camera's
// residuals: freeing all cameras at once would credit the others with its gain.
void ChooseTerms(RigState* s, const std::vector<MultiFrame>& frames, const MultiOptions& options,
                 MultiResult* result) {
  for (;;) {
    long long n = 0, n_c = 0;
    const double sse0 = RigSse(*s, frames, &n);
    double best_gain = 0;
    RigState best_state;
    bool found = false;
    for (const TermChoice& term : OpenTerms(*s, options)) {
      const int c = term.camera;
      RigState trial = *s;
      (term.k3 ? trial.k3 : trial.tangential)[c] = true;
      SolveRig(&trial, frames, options, result);
      long long n1 = 0;
      const double sse1 = RigSse(trial, frames, &n1);
      double gain = 0;
      bool pays = false;
      if (term.k3) {
        gain = util::BicGain(sse0, sse1, n, 1);
        pays = gain > kK3MinBicGain;
      } else {
        pays = TangentialPays(sse0, sse1, n, &gain);
      }
      const double rms0 = std::sqrt(2 * CameraSse(*s, frames, c, &n_c) / n_c);
      const double rms1 = std::sqrt(2 * CameraSse(trial, frames, c, &n_c) / n_c);
      auto& rep = result->camera_reports[c];
      TermReport& tried = term.k3 ? rep.k3 : rep.tangential;
      tried.tested = true;
      tried.rms_without_px = rms0;
      tried.rms_with_px = rms1;
      tried.bic_gain = gain;
      if (pays && gain > best_gain) {
        found = true;
        best_gain = gain;
        best_state = std::move(trial);
      }
    }
    if (!found) return;
    *s = std::move(best_state);
  }
}

// Why an automatically chosen term is kept or left out ("p1 p2 kept: its rms ... without them").
std::string TermWhy(const char* name, const char* pronoun, const TermReport& t) {
  return fmt::format(
      "{} {}: its rms {:.4f} px without {}, {:.4f} px with; the rig's BIC gain {:.1f}", name,
      t.fitted ? "kept" : "left out", t.rms_without_px, pronoun, t.rms_with_px, t.bic_gain);
}

// Per camera: the model kept and why.
void DescribeModels(const RigState& s, const MultiOptions& options, MultiResult* result) {
  for (int c = 0; c < s.nc(); ++c) {
    auto& rep = result->camera_reports[c];
    rep.tangential.fitted = s.tangential[c];
    rep.k3.fitted = s.k3[c];
    const std::string name = ModelName(s.num_distortion[c], s.tangential[c], s.k3[c]);
    if (s.fixed[c]) {
      rep.model = name + " (intrinsics fixed)";
      continue;
    }
    std::vector<std::string> why;
    if (options.tangential != TangentialModel::kAuto) {
      why.push_back(s.tangential[c] ? "--tangential free" : "--tangential zero");
    } else {
      why.push_back(TermWhy("p1 p2", "them", rep.tangential));
    }
    if (s.num_distortion[c] == 5 && options.k3 == K3Model::kZero) why.push_back("--k3 zero");
    if (rep.k3.tested) why.push_back(TermWhy("k3", "it", rep.k3));
    rep.model = fmt::format("{} ({})", name, fmt::join(why, "; "));
  }
}

// Cameras, views and per-camera RMS of the final state.
void CollectCameras(const std::vector<std::string>& names, const std::vector<MultiFrame>& frames,
                    const std::vector<camera::Camera>& cams, const RigState& s,
                    const MultiOptions& options, MultiResult* result) {
  const int nc = s.nc(), nf = s.nf();
  result->cameras.resize(nc);
  double sq_all = 0;
  long long n_all = 0;
  for (int c = 0; c < nc; ++c) {
    camera::Camera& cam = result->cameras[c];
    cam = cams[c];
    cam.name = names[c];
    cam.SetIntrinsicsBlock(s.intr[c], s.num_distortion[c]);
    cam.has_pose = true;
    cam.cam_from_world =
        c == 0 ? geometry::Rigid3d() : geometry::Rigid3d::FromRvecTvec(s.cam_r[c], s.cam_t[c]);
    double sq = 0;
    long long n = 0;
    auto& rep = result->camera_reports[c];
    for (int f = 0; f < nf; ++f) {
      const BoardView& v = frames[f].views[c];
      if (v.image_points.empty()) continue;
      MultiViewReport vr;
      vr.camera = c;
      vr.frame = f;
      vr.name = v.name;
      vr.image_points = v.image_points;
      vr.object_points = v.object_points;
      vr.corner_ids = v.corner_ids;
      vr.used = s.used[c][f];
      if (s.board_ok[f]) {
        vr.err_px = ViewErrors(s, frames, c, f);
        vr.rms_px = RmsOf(vr.err_px);
      } else {
        vr.err_px.assign(v.image_points.size(), 0.0f);
        vr.dropped_because = "no board pose (the board could not be placed in this view)";
      }
      if (!s.dropped_because[c][f].empty()) vr.dropped_because = s.dropped_because[c][f];
      if (vr.used) {
        ++rep.num_used;
        for (float e : vr.err_px) {
          sq += static_cast<double>(e) * e;
          ++n;
        }
      }
      result->views.push_back(std::move(vr));
    }
    rep.rms_px = n ? std::sqrt(sq / n) : 0.0;
    sq_all += sq;
    n_all += n;
    cam.rms_px = rep.rms_px;
    cam.notes["board"] = options.board.Describe();
    cam.notes["distortion_model"] = rep.model;
    cam.notes["rig_reference"] = names[0];
    cam.notes["rig_pose"] = "x_cam = R x_ref + t, ref = camera " + names[0];
    cam.notes["num_views"] = std::to_string(rep.num_used);
  }
  result->rms_px = n_all ? std::sqrt(sq_all / n_all) : 0.0;
  for (int f = 0; f < nf; ++f) {
    for (int c = 0; c < nc; ++c) {
      if (s.used[c][f]) {
        ++result->num_frames;
        break;
      }
    }
  }
}

// OpenCV's stereoCalibrate on the corners both cameras see in their shared used views, each
// camera's own calibrateCamera fit as the start, p1 p2 zero where neither camera kept them.
void CompareWithOpenCv(const std::vector<MultiFrame>& frames,
                       const std::vector<camera::Camera>& cams, const RigState& s,
                       const MultiResult& result, MultiPairReport* p) {
  const int i = p->i, j = p->j;
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> img_i, img_j;
  for (int f = 0; f < s.nf(); ++f) {
    if (!(s.used[i][f] && s.used[j][f])) continue;
    const BoardView& vi = frames[f].views[i];
    const BoardView& vj = frames[f].views[j];
    std::map<int, size_t> in_j;
    for (size_t k = 0; k < vj.corner_ids.size(); ++k) in_j[vj.corner_ids[k]] = k;
    std::vector<cv::Point3f> o;
    std::vector<cv::Point2f> pi, pj;
    for (size_t k = 0; k < vi.corner_ids.size(); ++k) {
      const auto it = in_j.find(vi.corner_ids[k]);
      if (it == in_j.end()) continue;
      o.push_back(vi.object_points[k]);
      pi.push_back(vi.image_points[k]);
      pj.push_back(vj.image_points[it->second]);
    }
    if (o.size() < 6) continue;
    obj.push_back(o);
    img_i.push_back(pi);
    img_j.push_back(pj);
  }
  if (obj.size() < 3) return;
  const bool zero_tangent = !s.tangential[i] && !s.tangential[j];
  const bool zero_k3 = !s.k3[i] && !s.k3[j];
  auto k_of = [](const camera::Camera& c) { return cv::Mat(camera::IntrinsicMatrix(c)); };
  auto d_of = [&](const camera::Camera& c) {
    cv::Mat d = camera::DistortionRow(c);
    if (zero_tangent) d.at<double>(2) = d.at<double>(3) = 0.0;
    if (zero_k3 && d.cols >= 5) d.at<double>(4) = 0.0;
    return d;
  };
  cv::Mat rot, t, e, fm;
  try {
    cv::Mat ki = k_of(cams[i]), kj = k_of(cams[j]), di = d_of(cams[i]), dj = d_of(cams[j]);
    p->opencv_rms_px = cv::stereoCalibrate(
        obj, img_i, img_j, ki, di, kj, dj, cv::Size(cams[i].width, cams[i].height), rot, t, e, fm,
        cv::CALIB_USE_INTRINSIC_GUESS | (zero_tangent ? cv::CALIB_ZERO_TANGENT_DIST : 0) |
            (zero_k3 ? cv::CALIB_FIX_K3 : 0));
  } catch (const cv::Exception&) {
    return;
  }
  Eigen::Matrix3d r;
  for (int u = 0; u < 3; ++u) {
    for (int v = 0; v < 3; ++v) r(u, v) = rot.at<double>(u, v);
  }
  const camera::Camera& a = result.cameras[i];
  const camera::Camera& b = result.cameras[j];
  p->has_opencv = true;
  p->opencv_rotation_deg =
      geometry::RotationAngleBetween(r, Eigen::Matrix3d::Identity()) * kRadToDeg;
  p->opencv_baseline_m = cv::norm(t);
  p->opencv_rotation_diff_deg =
      geometry::RotationAngleBetween(
          r, b.cam_from_world.rotation * a.cam_from_world.rotation.transpose()) *
      kRadToDeg;
}

// Rotation, baseline and shared views of every camera pair (and OpenCV's, when asked).
void CollectPairs(const std::vector<MultiFrame>& frames, const std::vector<camera::Camera>& cams,
                  const RigState& s, const MultiOptions& options, MultiResult* result) {
  for (int i = 0; i < s.nc(); ++i) {
    for (int j = i + 1; j < s.nc(); ++j) {
      MultiPairReport p;
      p.i = i;
      p.j = j;
      for (int f = 0; f < s.nf(); ++f) p.shared_views += s.used[i][f] && s.used[j][f] ? 1 : 0;
      const camera::Camera& a = result->cameras[i];
      const camera::Camera& b = result->cameras[j];
      p.rotation_deg = geometry::RotationAngleBetween(
                           b.cam_from_world.rotation * a.cam_from_world.rotation.transpose(),
                           Eigen::Matrix3d::Identity()) *
                       kRadToDeg;
      p.baseline_m = (a.CentreInWorld() - b.CentreInWorld()).norm();
      // Two cameras at one place see nothing in depth (ball and fuse refuse such a rig).
      FV_REQUIRE(p.baseline_m >= 1e-3,
                 "cameras '{}' and '{}' come out at one place ({:.2f} mm apart, turned {:.3f} "
                 "deg): were the same views given for both?",
                 a.name, b.name, 1000 * p.baseline_m, p.rotation_deg);
      if (options.compare_opencv && p.shared_views >= 3) {
        CompareWithOpenCv(frames, cams, s, *result, &p);
      }
      result->pairs.push_back(p);
    }
  }
}

void AddWarnings(int dropped_total, int max_drop, MultiResult* result) {
  for (const auto& rep : result->camera_reports) {
    if (rep.num_used < 8) {
      result->warnings.push_back(fmt::format(
          "camera '{}': only {} views; 10 or more spread over its image pin its intrinsics down",
          rep.name, rep.num_used));
    }
    if (rep.rms_px > 1.0) {
      result->warnings.push_back(fmt::format(
          "camera '{}': rms {:.2f} px is high (blur, a bent board or unsynchronized views?)",
          rep.name, rep.rms_px));
    }
  }
  if (dropped_total > 0 && dropped_total >= max_drop) {
    result->warnings.push_back(
        fmt::format("{} views were dropped as outliers (the most allowed)", dropped_total));
  }
}

}  // namespace

bool TangentialPays(double sse_without, double sse_with, long long num_residuals,
                    double* bic_gain) {
  const double gain = util::BicGain(sse_without, sse_with, num_residuals, 2);
  if (bic_gain) *bic_gain = gain;
  return gain > 0;
}

MultiResult CalibrateMultiFromFrames(const std::vector<std::string>& names,
                                     const std::vector<MultiFrame>& frames,
                                     const MultiOptions& options, const std::string& pairing) {
  options.Check();
  CheckFrames(names, frames);
  MultiResult result;
  result.pairing = pairing.empty() ? "paired by moment" : pairing;
  const std::vector<camera::Camera> cams =
      InitialIntrinsics(names, frames, options, &result.camera_reports);
  const PoseGrid pose = BoardPoses(cams, frames);
  const std::vector<geometry::Rigid3d> cam_from_ref =
      ChainCameras(names, frames, cams, pose, options, &result.camera_reports);
  RigState state = StartState(names, frames, cams, cam_from_ref, pose, options);
  const int max_drop =
      static_cast<int>(std::floor(options.max_drop_fraction * state.NumUsedViews()));
  int dropped_total = 0;
  AdjustRig(&state, frames, options, max_drop, &dropped_total, &result);
  ChooseTerms(&state, frames, options, &result);
  DescribeModels(state, options, &result);
  CollectCameras(names, frames, cams, state, options, &result);
  CollectPairs(frames, cams, state, options, &result);
  AddWarnings(dropped_total, max_drop, &result);
  return result;
}

MultiResult CalibrateMulti(const std::vector<CameraViews>& cameras, const MultiOptions& options) {
  options.Check();
  FV_REQUIRE(cameras.size() >= 2, "a rig needs at least 2 cameras (got {}); give --views twice",
             cameras.size());
  std::vector<CameraDetections> detections;
  std::vector<std::string> names;
  for (const auto& c : cameras) {
    FV_REQUIRE(std::find(names.begin(), names.end(), c.name) == names.end(),
               "camera name '{}' is given twice; give each --views a different NAME", c.name);
    names.push_back(c.name);
    detections.push_back(DetectCameraViews(c, options));
    const bool any = std::any_of(detections.back().views.begin(), detections.back().views.end(),
                                 [](const BoardView& v) { return !v.image_points.empty(); });
    FV_REQUIRE(any, "camera '{}': no {} found in any of the {} images of '{}' {}", c.name,
               options.board.Describe(), detections.back().views.size(), c.source,
               BoardNotFoundHint(ImageSource(c.source, options.source).Read(0), options.board));
    // A rig's cameras must see the same board points: on a larger chessboard OpenCV finds a part
    // of the given size, a different part in different views (poses off by whole squares).
    const LargerBoard& larger = detections.back().larger_board;
    FV_REQUIRE(larger.size.empty(),
               "camera '{}': '{}' shows a chessboard of {}, larger than the {}x{} given: a part "
               "of it is found, a different part in different views, and the rig's poses would "
               "be off by whole squares; give the board's own --cols and --rows",
               c.name, larger.view, larger.size, options.board.cols, options.board.rows);
  }
  std::string how;
  const auto frames = PairViews(detections, options.pairing, &how);
  return CalibrateMultiFromFrames(names, frames, options, how);
}

cv::Mat MultiCoveragePicture(const MultiResult& result, int camera) {
  FV_REQUIRE(camera >= 0 && camera < static_cast<int>(result.cameras.size()),
             "coverage picture: camera {} out of range", camera);
  const camera::Camera& cam = result.cameras[camera];
  const auto& rep = result.camera_reports[camera];
  const double scale = std::min(1.0, 960.0 / cam.width);
  const int w = static_cast<int>(std::lround(cam.width * scale));
  const int h = static_cast<int>(std::lround(cam.height * scale));
  const int left = 100, top = 56, right = 190, bottom = 48;
  cv::Mat img(h + top + bottom, w + left + right, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Rect area(left, top, w, h);
  img(area).setTo(cv::Scalar(48, 48, 48));
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  const cv::Scalar black(0, 0, 0);
  auto to_px = [&](const cv::Point2f& p) {
    return cv::Point(left + static_cast<int>(std::lround((p.x + 0.5) * scale - 0.5)),
                     top + static_cast<int>(std::lround((p.y + 0.5) * scale - 0.5)));
  };
  // Grid of 4x4 cells with the number of used corners in each.
  const int grid = 4;
  std::vector<int> counts(static_cast<size_t>(grid) * grid, 0);
  double max_err = 0.0;
  for (const auto& v : result.views) {
    if (v.camera != camera || !v.used) continue;
    for (size_t k = 0; k < v.image_points.size(); ++k) {
      const auto& p = v.image_points[k];
      const int gc = std::clamp(static_cast<int>(p.x * grid / cam.width), 0, grid - 1);
      const int gr = std::clamp(static_cast<int>(p.y * grid / cam.height), 0, grid - 1);
      ++counts[gr * grid + gc];
      max_err = std::max(max_err, static_cast<double>(v.err_px[k]));
    }
  }
  // Colour scale: 0 .. the larger of 1 px and 3 x the camera's RMS, capped at the worst corner.
  const double scale_px = std::max(0.5, std::min(max_err, std::max(1.0, 3.0 * rep.rms_px)));
  auto colour = [&](double e) {
    cv::Mat v(1, 1, CV_8U, cv::Scalar(std::clamp(e / scale_px, 0.0, 1.0) * 255));
    cv::Mat c;
    cv::applyColorMap(v, c, cv::COLORMAP_TURBO);
    const cv::Vec3b b = c.at<cv::Vec3b>(0, 0);
    return cv::Scalar(b[0], b[1], b[2]);
  };
  for (const auto& v : result.views) {
    if (v.camera != camera || v.used) continue;
    for (const auto& p : v.image_points) {
      const cv::Point q = to_px(p);
      cv::line(img, q + cv::Point(-3, -3), q + cv::Point(3, 3), cv::Scalar(150, 150, 150), 1);
      cv::line(img, q + cv::Point(-3, 3), q + cv::Point(3, -3), cv::Scalar(150, 150, 150), 1);
    }
  }
  for (const auto& v : result.views) {
    if (v.camera != camera || !v.used) continue;
    for (size_t k = 0; k < v.image_points.size(); ++k) {
      cv::circle(img, to_px(v.image_points[k]), 2, colour(v.err_px[k]), cv::FILLED, cv::LINE_AA);
    }
  }
  for (int g = 1; g < grid; ++g) {
    const int x = left + g * w / grid, y = top + g * h / grid;
    cv::line(img, {x, top}, {x, top + h}, cv::Scalar(110, 110, 110), 1);
    cv::line(img, {left, y}, {left + w, y}, cv::Scalar(110, 110, 110), 1);
  }
  for (int r = 0; r < grid; ++r) {
    for (int c = 0; c < grid; ++c) {
      const std::string s = std::to_string(counts[r * grid + c]);
      const cv::Point at(left + c * w / grid + 4, top + r * h / grid + 16);
      cv::putText(img, s, at, font, 0.45, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
      cv::putText(img, s, at, font, 0.45, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    }
  }
  cv::rectangle(img, area, black, 1);
  // Axes: ticks in image pixels.
  const int span = std::max(cam.width, cam.height);
  const int step = span > 3000 ? 1000 : span > 1500 ? 500 : span > 600 ? 200 : 100;
  for (int u = 0; u <= cam.width; u += step) {
    const int x = left + static_cast<int>(std::lround(u * scale));
    cv::line(img, {x, top + h}, {x, top + h + 5}, black, 1);
    cv::putText(img, std::to_string(u), {x - 10, top + h + 20}, font, 0.4, black, 1, cv::LINE_AA);
  }
  for (int v = 0; v <= cam.height; v += step) {
    const int y = top + static_cast<int>(std::lround(v * scale));
    cv::line(img, {left - 5, y}, {left, y}, black, 1);
    cv::putText(img, std::to_string(v), {left - 44, y + 4}, font, 0.4, black, 1, cv::LINE_AA);
  }
  cv::putText(img, "u (px)", {left + w / 2 - 20, top + h + 40}, font, 0.45, black, 1, cv::LINE_AA);
  cv::putText(img, "v (px)", {4, top + h / 2 + 4}, font, 0.45, black, 1, cv::LINE_AA);
  cv::putText(img,
              fmt::format("camera {}: {} of {} views used, rms {:.3f} px ({}x{} px)", rep.name,
                          rep.num_used, rep.num_found, rep.rms_px, cam.width, cam.height),
              {left, 20}, font, 0.5, black, 1, cv::LINE_AA);
  cv::putText(img, "dots: board corners coloured by reprojection error; numbers: corners per cell",
              {left, 40}, font, 0.4, black, 1, cv::LINE_AA);
  // Legend: colour bar.
  const int bx = left + w + 30, by = top + 10, bh = std::max(100, h - 80);
  for (int y = 0; y < bh; ++y) {
    const double e = scale_px * (1.0 - static_cast<double>(y) / (bh - 1));
    cv::line(img, {bx, by + y}, {bx + 18, by + y}, colour(e), 1);
  }
  cv::rectangle(img, cv::Rect(bx, by, 19, bh), black, 1);
  cv::putText(img, fmt::format("{:.2f} px", scale_px), {bx + 24, by + 8}, font, 0.4, black, 1,
              cv::LINE_AA);
  cv::putText(img, fmt::format("{:.2f} px", scale_px / 2), {bx + 24, by + bh / 2 + 4}, font, 0.4,
              black, 1, cv::LINE_AA);
  cv::putText(img, "0 px", {bx + 24, by + bh}, font, 0.4, black, 1, cv::LINE_AA);
  cv::putText(img, "error", {bx - 4, by + bh + 20}, font, 0.4, black, 1, cv::LINE_AA);
  const cv::Point xq(bx + 6, by + bh + 38);
  cv::line(img, xq + cv::Point(-3, -3), xq + cv::Point(3, 3), cv::Scalar(150, 150, 150), 1);
  cv::line(img, xq + cv::Point(-3, 3), xq + cv::Point(3, -3), cv::Scalar(150, 150, 150), 1);
  cv::putText(img, "dropped view", {bx + 14, by + bh + 42}, font, 0.4, black, 1, cv::LINE_AA);
  return img;
}

void WriteMultiCorners(const std::string& path, const MultiResult& result) {
  util::AtomicWrite(
      path,
      [&](const std::string& tmp) {
        std::ofstream out(tmp);
        FV_REQUIRE(out.good(), "corners file '{}' cannot be written", path);
        out << "camera,moment,image,corner_id,u_px,v_px,x_m,y_m,err_px,used\n";
        for (const auto& v : result.views) {
          for (size_t k = 0; k < v.image_points.size(); ++k) {
            out << fmt::format("{},{},{},{},{:.4f},{:.4f},{:.6f},{:.6f},{:.4f},{}\n",
                               result.camera_reports[v.camera].name, v.frame, v.name,
                               k < v.corner_ids.size() ? v.corner_ids[k] : static_cast<int>(k),
                               v.image_points[k].x, v.image_points[k].y, v.object_points[k].x,
                               v.object_points[k].y, v.err_px[k], v.used ? 1 : 0);
          }
        }
        FV_REQUIRE(out.good(), "corners file '{}' cannot be written", path);
      },
      "corners file");
}

}  // namespace fv::calib
