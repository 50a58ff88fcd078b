// Foot points of partly hidden people: a box much shorter than the person's height around it (the
// median box height of the track within window_s) shows the head and body while the legs are
// behind someone nearer the camera or below the image's edge, so its bottom is not the foot (a box
// at the image's top edge is left: its top may not be the head). The
// foot is taken at the person's height below the box's top (the head stays in view) and mapped to
// the ground again. The same model as the stitcher's ends (players.h, StitchOptions), applied to
// every row before the ground smoothing; the speeds and distances of `stats` come from them.
#pragma once

#include <string>
#include <vector>

#include "fieldvision/camera/camera.h"
#include "fieldvision/track/mot.h"

namespace fv::track {

struct HiddenFeetOptions {
  bool enabled = true;
  double full_height_ratio = 0.85;  // a box under this share of the median height is partly hidden
  double window_s = 3.0;            // the median over this span centred on the row
  // A box wider than this times the median width is not a hidden person (someone lying, diving,
  // or two people in one box) and keeps its foot point.
  double max_width_ratio = 1.25;
  void Check() const;  // throws fv::Error naming the bad field
};

// Moves x_m, y_m of the partly hidden rows among `measured` (empty: every row) to the foot at the
// person's height below the box's top, through `camera` (posed) with its foot offset
// (FootOnGround); the median heights come from the measured rows of each id. Returns how many
// rows were moved.
int MendHiddenFeet(std::vector<TrackRow>& rows, const std::vector<bool>& measured,
                   const camera::Camera& camera, double foot_offset_m, double fps,
                   const HiddenFeetOptions& options = {});

}  // namespace fv::track
