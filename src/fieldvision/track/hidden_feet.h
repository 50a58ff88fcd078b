// Foot points of partly hidden people: each box implies a height, where the ray through its top
// passes over its foot point on the ground; a box implying much less than the person's height
// (the median over the track's boxes within window_s; the same near or far, so a person walking
// towards the camera or a track's end needs no trend) shows the head and body while the legs are
// behind someone nearer the camera or below the image's edge, so its bottom is not the foot. The
// foot is taken where the top's ray is at the person's height, before the ground smoothing; the
// speeds and distances of `stats` use it. A hiding longer than half the window sets the median
// itself and is left. The stitcher's model of a partly hidden end (players.h, StitchOptions).
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/track/mot.h"

namespace fv::track {

struct HiddenFeetOptions {
  bool enabled = true;
  double full_height_ratio = 0.85;  // a box implying under this share of it is partly hidden
  double window_s = 3.0;            // the person's height: median within half this of the row
  // A box wider than this times the median width there is not a hidden person (someone lying,
  // diving, or two people in one box) and keeps its foot point.
  double max_width_ratio = 1.25;
  double top_edge_px = 2.0;  // a box whose top is this near the image's top may have lost the head
  void Check() const;        // throws fv::Error naming the bad field
};

// Moves x_m, y_m of the partly hidden rows to the foot below the box's top at the person's height,
// through `camera` (posed) with its foot offset (as FootOnGround); the person's height comes from
// the rows flagged in `measured` (empty: every row); `frame_box` gives a row's box in its frame's
// pixels for the top-edge check (a moving camera). Returns how many rows were moved.
int MendHiddenFeet(std::vector<TrackRow>& rows, const std::vector<bool>& measured,
                   const camera::Camera& camera, double foot_offset_m, double fps,
                   const HiddenFeetOptions& options = {}, const FrameBoxOf& frame_box = {});

}  // namespace fv::track
