// Sub-pixel centre of a ball blob from its outline, not its colour centroid (which shading,
// highlights and occlusion bias): sub-pixel edge points along rays from a rough centre (the 0.5
// crossing of each ray's profile between its own inside and outside colours, so the ball's
// shading and a changing background do not bias it), then a robust fit that keeps only the free
// part of the outline (occluders' edges are outliers). With a camera the fit is of the cone of
// rays tangent to the sphere (unit rays v with v . w = 1, linear least squares, w = axis / cos
// alpha), whose axis projects exactly to the sphere centre, so it is unbiased in perspective and
// under distortion; without one it is a geometric circle fit (Gauss-Newton). A motion-blurred
// ball (an elongated outline) gets an ellipse fit (cv::fitEllipseDirect) whose centre is the
// mid-exposure position. The uncertainty is the centre's standard deviation from the residuals
// and the Jacobian of the circle. Ray casting as in Hanek's contracting-curve papers and RoboCup
// ball detectors (B-Human code release 2019, "ball perceptor").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/detect/colour.h"

namespace fv::detect {

struct BallFitOptions {
  double min_contrast = 20.0;     // BGR distance between a ray's inside and outside colours
  double inlier_px = 0.6;         // outline points farther than this from the fit are outliers
                                  // (plus 3 % of the radius)
  int ransac_iterations = 60;     // for the first, rough outline
  double blur_min_aspect = 1.15;  // an outline this elongated that fits an ellipse is blurred
  // Outline points inside the fit are inliers within this share of the band only (inlier_px
  // plus 3 % of the radius): a print's line, the shading's terminator and an occluder's edge lie
  // inside a ball's silhouette, never outside it, so the fit keeps to the outer outline (the
  // silhouette). The checks' inliers (outside share, dents) come from a circle with the same band
  // both ways, out of which a polygon's corners stick. 1: the same band both ways.
  double inside_share = 0.7;
  // A step whose inside is not of the ball's colour class is still the silhouette when its
  // inside is the ball in shade: within shade_max_offset (BGR units) of the line through black
  // and the mean colour of the ball's class pixels, at shade_min_brightness..1 x their
  // brightness. Shading scales a matte surface's colour; a print, the background and a board of
  // a nearby hue lie off that line. Without this the shaded side's outline points fall on the
  // terminator inside the ball and pull the circle towards the lit side. 0: off. Measured
  // (offset 0 / 12 / 15 / 20 / 30; `eval detect` centre error median on the low-sun-kick render,
  // MSL photo recall): 0.266 / 0.203 / 0.199 / 0.191 / 0.198 px, 0.718 / 0.709 / 0.709 / 0.701 /
  // 0.692; the kick render and the SSL photos alike at 0..20.
  double shade_max_offset = 15.0;
  double shade_min_brightness = 0.2;
  // A step onto the field whose inside holds a band darker than shadow_band_ratio x both of the
  // step's sides, not the ball in shade, is the edge of the ball's contact shadow on the grass:
  // the ball's underside and the shadow merge, its outline there is not seen, and the ray gives
  // no point. 0: off. Measured with `eval detect` on the low-sun renders, balls resting on the
  // ground (centre error median, mean vertical error; ratio 0 / 0.7 / 0.8 / 0.9): low-sun kick
  // seed 2 0.50 / 0.33 / 0.25 / 0.28 px, +0.31 / +0.22 / +0.03 / -0.03 px; seed 1 0.23 / 0.23 /
  // 0.19 / 0.15 px; the plain kick 0.126 / 0.109 / 0.117 / 0.096 px (p90 0.27 / 0.25 / 0.26 /
  // 0.41); balls in the air and the photos unchanged. `ball` on seven kick renders (low-sun
  // seeds 1, 2, 3, 4, 6, 7 and the plain kick), p95 of the 3D error: 3.0 / 8.9 / 6.6 / 7.6 / 7.7
  // / 5.9 / 2.5 mm -> 2.5 / 4.0 / 3.9 / 3.5 / 2.9 / 3.9 / 1.7 mm; low-sun static scenes mixed (mean
  // 3.45 -> 3.60, 3.13 -> 2.66, 3.72 -> 2.91 mm).
  double shadow_band_ratio = 0.8;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

struct BallFit {
  bool ok = false;
  std::string failure;  // why not ok
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double radius_px = 0.0;
  double sigma_px = 0.0;  // standard deviation of the centre (each axis)
  double rms_px = 0.0;    // RMS distance of the inlier outline points from the fit
  int rays = 0;
  int edges = 0;                 // rays with an outline point
  int inliers = 0;               // outline points on the fit
  double inlier_fraction = 0.0;  // inliers / rays inside the image (at least half the rays)
  // Rays where the colour goes on beyond the fit (outline outside it, or ball-coloured outside):
  // high for shapes that are not discs (a cone's apex), low for occluded balls.
  double outside_fraction = 0.0;
  // Arcs (2+ rays) of the outline inside the fit: an occluder makes one or two, a polygon more.
  int dents = 0;
  bool blurred = false;
  double blur_length_px = 0.0;               // major minus minor axis of the blurred outline
  std::vector<Eigen::Vector2d> edge_points;  // for drawing
  std::vector<char> edge_inlier;
  std::string Summary() const;
};

// Refines a ball seen around `rough_centre_px` with radius about `rough_radius_px`. `ball_bit`
// is the ball's class in `table`. `camera` may be null (pixel-space fit).
BallFit FitBall(const cv::Mat& bgr, const ColourTable& table, uint8_t ball_bit,
                const Eigen::Vector2d& rough_centre_px, double rough_radius_px,
                const camera::Camera* camera, const BallFitOptions& options = {});

// Robust geometric circle fit of points (used by FitBall; exposed for tests): the initial guess
// is refined by Gauss-Newton with outliers (farther than inlier_px outside the circle, or
// inside_px inside it; inside_px < 0: inlier_px) dropped; `inlier` receives the final inlier
// flags. Returns false when fewer than 3 inliers remain.
bool FitCircle(const std::vector<Eigen::Vector2d>& points, double inlier_px,
               Eigen::Vector2d* centre, double* radius, std::vector<char>* inlier,
               double inside_px = -1.0);

// The circle through three points; false when they are (nearly) collinear.
bool CircleFrom3(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                 Eigen::Vector2d* centre, double* radius);

// RANSAC on point triples (a fixed, deterministic sequence of `iterations` draws) with inlier
// threshold `thr`, then FitCircle on the best triple's inliers. False with fewer than 3 inliers.
bool RansacCircle(const std::vector<Eigen::Vector2d>& pts, double thr, int iterations,
                  Eigen::Vector2d* centre, double* radius, std::vector<char>* inlier);

}  // namespace fv::detect
