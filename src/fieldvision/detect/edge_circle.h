// A circle near an expected one from colour edges alone, for a ball whose colour class does not
// separate it from what lies behind it (a yellow ball in front of a yellow board, a ball in deep
// shade): along rays from the expected centre, the strongest colour step between 0.6 and 1.45
// expected radii (sub-pixel by a parabola through the peak), then RANSAC over point triples whose
// circle agrees with the expected one (radius and centre), refined by the robust circle fit of
// ball_fit.h. Only meaningful with a good expectation (a tracked ball), as in the guided search
// of RoboCup ball perceptors (B-Human code release 2019) and contour trackers (Isard & Blake,
// CONDENSATION, 1998).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace fv::detect {

struct EdgeCircleOptions {
  double min_step = 20.0;          // BGR distance across 1 px at an edge point
  double max_radius_change = 0.2;  // share of the expected radius
  double max_shift_radii = 1.0;    // centre from the expected one, in expected radii
  double inlier_px = 0.6;          // plus 3 % of the radius
  int ransac_iterations = 200;
  void Check() const;  // throws fv::Error naming the bad field
};

struct EdgeCircle {
  bool ok = false;
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double radius_px = 0.0;
  double sigma_px = 0.0;         // standard deviation of the centre (each axis)
  double rms_px = 0.0;           // of the inlier edge points
  double inlier_fraction = 0.0;  // inlier edge points / rays
};

// The circle nearest (centre_px, radius_px) in a BGR image; reads pixels up to 1.5 radii + 2 px
// from centre_px (within the image). Not ok when too few rays agree.
EdgeCircle FitEdgeCircle(const cv::Mat& bgr, const Eigen::Vector2d& centre_px, double radius_px,
                         const EdgeCircleOptions& options = {});

}  // namespace fv::detect
