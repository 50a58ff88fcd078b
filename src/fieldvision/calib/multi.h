// Calibration of several cameras at once (a rig) from synchronized views of one chessboard or
// ChArUco board: corners per camera (board.h), views paired across cameras by sorted order or
// frame number, intrinsics per camera (OpenCV's calibrateCamera, intrinsics.h), board poses per
// view (IPPE PnP), relative poses of camera pairs from their shared views (the candidate that
// best transfers the board between the two, in pixels), chained from the first camera through a
// maximum spanning tree of shared-view counts, then one Ceres bundle adjustment of every camera's
// intrinsics and pose and every board pose (Huber loss), outlier views dropped and named, p1 p2
// kept per camera only where they pay (forward selection by BIC, Schwarz 1978). The
// method of multi-camera toolboxes such as MC-Calib (Rameau et al., "MC-Calib: a generic and
// robust calibration toolbox for multi-camera systems", CVIU 2022) and anipose.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/calib/board.h"
#include "fieldvision/calib/intrinsics.h"
#include "fieldvision/camera/camera.h"

namespace fv::calib {

// One camera's images: NAME=GLOB_OR_DIR_OR_VIDEO on the command line.
struct CameraViews {
  std::string name;
  std::string source;
};
// Parses "NAME=SOURCE"; throws naming the argument when the name or source is missing.
CameraViews ParseCameraViews(const std::string& arg);

// How views of different cameras are matched: kFrameNumber by the last number in each file name
// (left07.jpg with right07.jpg; a video's frame number), kOrder by position in the sorted list,
// kAuto by frame number when every name has one, else by order.
enum class Pairing { kAuto, kOrder, kFrameNumber };
Pairing ParsePairing(const std::string& name);

// Tangential distortion (p1 p2) in the rig's fit: chosen per camera, always fitted, or zero.
using TangentialModel = TermModel;
inline TangentialModel ParseTangentialModel(const std::string& name) {
  return ParseTermModel(name, "tangential model");
}

// Whether fitting one camera's p1 p2 lowers the sum of squared corner residuals (px^2) enough for
// 2 more parameters: the Bayesian information criterion, n ln(sse_without / sse_with) > 2 ln n,
// n the number of residuals (2 per corner). Its value is returned in *bic_gain when given.
bool TangentialPays(double sse_without, double sse_with, long long num_residuals,
                    double* bic_gain = nullptr);

struct MultiOptions {
  BoardSpec board;
  DetectOptions detect;
  ImageSourceOptions source;
  Pairing pairing = Pairing::kAuto;
  int num_distortion = 5;  // 4, 5, 8, 12 or 14 OpenCV coefficients per camera
  // Tangential distortion p1 p2 per camera. Fitting them when a lens has none costs
  // principal-point accuracy (they trade off against it), and with it the relative rotations
  // (1 px of principal point is about 1/f rad of rotation). kAuto fits the rig without them, then
  // frees them one camera at a time, the camera that lowers the rig's error most first, while
  // they pay for their 2 parameters (TangentialPays on the whole rig's residuals).
  TangentialModel tangential = TangentialModel::kAuto;
  // k3 per camera with 5 coefficients (other models keep it): kFree (OpenCV's) fits it; kZero
  // leaves it out; kAuto chooses it per camera in the same forward selection as p1 p2, kept only on
  // very strong evidence (kK3MinBicGain). A rig whose boards stay off the image corners
  // extrapolates k3 there (IntrinsicsOptions::k3 has the measurements of each choice on real and
  // projected views).
  K3Model k3 = K3Model::kAuto;
  bool refine_intrinsics = true;  // intrinsics free in the bundle adjustment
  // Cameras whose intrinsics are known (by name): kept fixed, not calibrated again.
  std::map<std::string, camera::Camera> known_intrinsics;
  double loss_px = 1.0;  // Huber scale of the bundle adjustment
  // A view (one camera, one moment) is dropped when its RMS exceeds both outlier_factor x the
  // median view RMS and outlier_min_px, at most max_drop_fraction of the views.
  double outlier_factor = 4.0;
  double outlier_min_px = 1.5;
  double max_drop_fraction = 0.3;
  int min_shared_views = 2;     // moments two cameras must share to link them in the spanning tree
  int min_views = 3;            // views with the board per camera (for its intrinsics)
  int max_iterations = 200;     // of each bundle adjustment
  bool compare_opencv = false;  // also run cv::stereoCalibrate on every pair (MultiPairReport)
  bool progress = true;         // progress on stderr while detecting
  void Check() const;
};

// One camera's detections with the key each view pairs on.
struct CameraDetections {
  std::string name;
  std::string source;
  std::vector<BoardView> views;  // every image; image_points empty where the board was not found
  std::vector<long long> frame_numbers;  // last number in each name; -1 when it has none
  LargerBoard larger_board;              // a larger chessboard in its images (board.h)
};

// Reads and detects the board in every image of one camera.
CameraDetections DetectCameraViews(const CameraViews& camera, const MultiOptions& options);

// The board at one moment: views[c] is camera c's view (image_points empty when unseen).
struct MultiFrame {
  std::string key;  // "frame 7" or "#3"
  std::vector<BoardView> views;
};

// Pairs the cameras' views into moments. Throws fv::Error naming the camera when views cannot be
// paired (different counts without frame numbers, no common frame numbers).
std::vector<MultiFrame> PairViews(const std::vector<CameraDetections>& cameras, Pairing pairing,
                                  std::string* how = nullptr);

struct MultiViewReport {
  int camera = 0;
  int frame = 0;
  std::string name;  // image name
  std::vector<cv::Point2f> image_points;
  std::vector<cv::Point3f> object_points;  // board corners (metres)
  std::vector<int> corner_ids;
  std::vector<float> err_px;  // per corner, final fit
  double rms_px = 0.0;
  bool used = true;
  std::string dropped_because;
};

// One optional lens term of a camera in the rig (p1 p2, or k3): whether it is fitted, and where
// the automatic choice tried it, the camera's RMS without and with it and the rig's BIC gain.
struct TermReport {
  bool fitted = false, tested = false;
  double rms_without_px = 0.0, rms_with_px = 0.0, bic_gain = 0.0;
};

struct MultiCameraReport {
  std::string name;
  int num_images = 0, num_found = 0, num_used = 0;
  double own_rms_px = 0.0;  // its own calibrateCamera fit, before the joint adjustment
  // With 5 coefficients: how far apart its own fits with and without k3 put the image's corners
  // (IntrinsicsResult::k3_corner_shift_px; 0 when not compared): where its boards stayed off the
  // corners the model is extrapolated there.
  double own_k3_corner_shift_px = 0.0;
  double rms_px = 0.0;   // joint fit, used views
  int tree_parent = -1;  // camera it was chained from (-1: the reference)
  int tree_shared_views = 0;
  // The distortion model kept: "k1 k2 p1 p2 k3" and why ("fixed", "--tangential zero", or the
  // camera's RMS without and with p1 p2, and k3, and the rig's BIC gain of the automatic choice).
  std::string model;
  TermReport tangential;  // p1 p2
  TermReport k3;          // with 5 coefficients
};

struct MultiPairReport {
  int i = 0, j = 0;
  int shared_views = 0;
  double rotation_deg = 0.0;  // angle of R_j R_i^T
  double baseline_m = 0.0;    // distance of the camera centres
  // With MultiOptions::compare_opencv: OpenCV's stereoCalibrate on the pair's shared used views
  // (each camera's intrinsics from calibrateCamera as the start), the baseline of the check.
  bool has_opencv = false;
  double opencv_rotation_deg = 0.0, opencv_baseline_m = 0.0, opencv_rms_px = 0.0;
  double opencv_rotation_diff_deg = 0.0;  // angle between our relative rotation and OpenCV's
};

struct MultiResult {
  // Intrinsics and pose in the first camera's frame (x_cam = R x_ref + t; first: identity).
  std::vector<camera::Camera> cameras;
  std::vector<MultiCameraReport> camera_reports;
  std::vector<MultiPairReport> pairs;
  std::vector<MultiViewReport> views;  // every view with the board
  std::string pairing;                 // how views were paired
  int num_frames = 0;                  // moments with the board in at least one camera
  int num_adjustments = 0;
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  double rms_px = 0.0;  // over every used corner
  std::vector<std::string> warnings;
  std::string Summary() const;
};

// The joint calibration of paired moments; names[c] names camera c. Throws fv::Error naming the
// camera when it has too few views or never sees the board together with the others.
MultiResult CalibrateMultiFromFrames(const std::vector<std::string>& names,
                                     const std::vector<MultiFrame>& frames,
                                     const MultiOptions& options, const std::string& pairing = "");

// Detection, pairing and calibration of 2..N cameras.
MultiResult CalibrateMulti(const std::vector<CameraViews>& cameras, const MultiOptions& options);

// Camera c's coverage picture: its image area with every used corner coloured by its error,
// dropped views' corners in grey, a grid with corner counts per cell, axes in pixels and a legend.
cv::Mat MultiCoveragePicture(const MultiResult& result, int camera);

// The detected corners of every view: camera,frame,image,corner_id,u_px,v_px,x_m,y_m,err_px,used.
// Written to a temporary file, then renamed; throws naming the path.
void WriteMultiCorners(const std::string& path, const MultiResult& result);

}  // namespace fv::calib
