// The region check of a ball candidate: what a real ball looks like once its colour blob is
// taken whole. Around a blob, the ball-coloured pixels (full resolution) that touch it are
// gathered and grown by the ball's own colour (seeded region growing, Adams & Bischof, PAMI 1994),
// gaps from a print, seams or a highlight are closed and holes filled; the convex part
// of the region's outline gets a robust circle (RANSAC + geometric fit), so an occluder's edge or
// the image border does not pull it. The measurements say how disc-like the region is: the share
// of the circle's angle with outline on it, the share of the disc that is filled, what spills
// beyond it and how much ball colour lies in a ring around it (a part of a larger object).
// After RoboCup region-based ball perceptors (e.g. B-Human 2019, Nao-Team HTWK) and the
// hole-filling of ssl-vision's blob stage.
#pragma once

#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/detect/colour.h"

namespace fv::detect {

struct BallRegionOptions {
  double gather_fraction = 0.5;  // other blobs within this share of the radius (+2 px) join
  double grow_fraction = 0.3;    // widened-class pixels join within this share of the radius
  double close_fraction = 0.2;   // closing radius as a share of the radius (print, seams), <= 4 px
  double hull_tolerance_px = 1.0;  // outline points this near the convex hull are "convex"
  double inlier_px = 0.8;          // circle inliers: within this plus 6 % of the radius
  // ... and, inside the circle, within this share of that band only: what is not the disc's
  // outline (a print's line, the shading's terminator, an occluder) lies inside it, never
  // outside, so the circle is fitted to the outer outline. The extent (corners) is measured
  // against the circle with the same band both ways. 1: the same band both ways.
  double inside_share = 0.6;
  double ring_inner = 1.35;  // leak ring, in radii
  double ring_outer = 1.9;
  // Pixels darker than this (max of B, G, R) hide the ball rather than frame it: a black robot in
  // front of it, a fisheye lens's dark border. The circle's angles with such pixels just outside
  // it, and the disc's dark pixels, count neither for nor against the outline and the fill.
  // 0 turns this off.
  int hidden_value = 40;
  double min_seen = 0.4;  // least share of the circle's angles seen (not outside, not hidden)
  // A region seen less than this is partly seen (`BallRegion::partly_seen`): a ball held in a
  // robot's handler or behind its bumper, whose visible cap is under half its outline. What
  // hides a ball stands on the ground in front of it, so the part seen must be the top
  // (min_partly_seen_rise), and its centre must lie in the image (a circle extrapolated from a
  // short arc beyond the image's edge is too loosely fixed to report). A lamp cut by the image's
  // top edge is neither.
  double well_seen = 0.5;
  // ... and its seen part must be the circle's top: the mean of -sin over the seen angles (image
  // rows down) at least this. A cap seen from straight above gives sin(pi s) / (pi s) (0.64 at
  // half the circle, s the share seen), an occluder's edge tilted by 50 deg about 0.4; a lamp cut
  // by the image's top edge shows its lower part (below 0). -1: any part.
  double min_partly_seen_rise = 0.4;
  // Growth by the ball's own colour (seeded region growing): pixels within own_reach radii of
  // the region join, when connected to it, if their CIELAB colour is nearer the region's median
  // colour than the surroundings' and within own_share of the distance between the two (and at
  // most own_max_delta_e). A ball whose colour only partly falls in the class (white balance,
  // shading, a reddish orange) is taken whole. own_reach 0 turns this off.
  double own_reach = 1.0;
  double own_share = 0.3;
  double own_max_delta_e = 20.0;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

struct BallRegion {
  bool ok = false;
  std::string failure;  // why not ok
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double radius_px = 0.0;
  double sigma_px = 0.0;     // standard deviation of the centre (each axis), from the residuals
  double rms_px = 0.0;       // RMS distance of the inlier outline points from the circle
  double area_px = 0.0;      // the closed, filled region
  double arc_cover = 0.0;    // share of the seen angle bins around the circle with an inlier point
  double fill = 0.0;         // share of the seen disc (inside the image, not hidden) in the region
  double seen = 0.0;         // share of the circle's angle bins not outside the image or hidden
  bool partly_seen = false;  // seen < well_seen
  double seen_rise = 0.0;    // how far up the seen part lies: mean -sin of its angles (1: top)
  double spill = 0.0;        // region area beyond 1.25 r + 1 px, as a share of the disc area
  double leak = 0.0;         // ball-coloured share of the ring ring_inner..ring_outer radii
  // Share of the convex outline points farther out than the circle (beyond the inlier band): a
  // corner or an apex (a cone, a robot's part) sticks out; an occluder's edge lies inside.
  double outside = 0.0;
  // The convex outline's second largest distance from the centre, in radii: about 1 for a disc,
  // 1.41 for a square's corners, more for a triangle's apex.
  double extent = 0.0;
  double purity = 0.0;  // ball-coloured share of the region before closing and filling
  // CIELAB distance (Delta E 1976) between the median colours of the disc's ball-class pixels
  // (inner 80 %; all of them when none is) and of the leak ring's pixels outside the ball class:
  // a ball's colour stands out from what is around it, a patch of a wall does not. The print
  // and the shaded side are left out (a yellow ball's shadow is olive, near the grass).
  double contrast = 0.0;
  // The hue part of that difference (CIE94 Delta H): what shading and exposure hardly change.
  double hue_contrast = 0.0;
  // The disc's chroma (CIELAB C*) minus the ring's, and the ring's own chroma and lightness (L*):
  // a coloured ball against grey stands differs from them in chroma, not in hue.
  double chroma_contrast = 0.0;
  double ring_chroma = 0.0;
  double ring_lightness = 0.0;
  // Share of the leak ring's pixels in the colour spec's "field" or "line" classes (0 without
  // them): a ball on the field is set apart by the classes themselves. Dark pixels (a robot
  // behind the ball, hidden_value) hide the field and are left out, at most half the ring.
  double field_ring = 0.0;
  double grass_ring = 0.0;  // the same share in the "field" class alone (not its lines)
  double solidity = 0.0;    // region area / convex hull area
  int outline_points = 0;   // convex outline points used by the circle fit
  int inliers = 0;
  // Set by the detector: the disc differs from the camera's background where a ring around it does
  // not (background.h), evidence of its own where the colour contrast is low.
  bool apart_from_background = false;
  std::string Summary() const;
};

// Analyses the blob whose bounds (full-resolution pixels) are `seed_box`; only pixels inside
// `limit` are read (the whole image when empty). `table`'s ball class is the core colour (leak,
// purity); class `grow_bit` (0: its ball class) of `grow_table` (null: none) the widened class the
// region grows through (`table` itself when it holds that class too: its lookups are reused).
BallRegion AnalyseBallRegion(const cv::Mat& bgr, const ColourTable& table, uint8_t ball_bit,
                             const cv::Rect& seed_box, const cv::Rect& limit,
                             const BallRegionOptions& options = {},
                             const ColourTable* grow_table = nullptr, uint8_t grow_bit = 0);

}  // namespace fv::detect
