// Refining a placed rig against the painted lines seen by all of its cameras: one rigid
// correction of the rig's world pose (the cameras' relative poses kept), found by minimising the
// ground distance of every camera's line pixels to the nearest line centreline (the distance table
// and the coarse-to-fine Cauchy stages of lines.h, summed over the cameras). A few noisy clicks
// place the rig within a few centimetres (rig_place.h); thousands of line pixels in several
// cameras, seen from different sides of the field, pin it down to millimetres.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/calib/lines.h"
#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"

namespace fv::calib {

struct RigRefineResult {
  std::vector<camera::Camera> cameras;  // refined rig (the input when not accepted)
  bool accepted = false;
  std::string status;  // why not accepted
  // Per camera (no pixels: zeros).
  std::vector<int> num_line_pixels;
  std::vector<LineErrorStats> before, after;
  geometry::Rigid3d correction;  // new cam_from_world = old cam_from_world * correction
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  double moved_m = 0.0;      // largest camera centre change
  double rotated_deg = 0.0;  // rotation of the rig
  std::string Summary() const;
};

// rig: cameras with world poses (e.g. PlaceRig's); pixels[i]: camera i's line pixels (may be
// empty). Throws fv::Error when a camera has no pose or the lists differ in size; too few line
// pixels over all cameras is a result with accepted = false.
RigRefineResult RefineRigWithLinePixels(const std::vector<camera::Camera>& rig,
                                        const std::vector<std::vector<Eigen::Vector2d>>& pixels,
                                        const field::FieldModel& field,
                                        const RefineOptions& options = {});

// The same from frames: images[i] is camera i's frame (empty Mat: no frame for that camera).
RigRefineResult RefineRigWithLines(const std::vector<camera::Camera>& rig,
                                   const std::vector<cv::Mat>& images,
                                   const field::FieldModel& field,
                                   const RefineOptions& options = {});

}  // namespace fv::calib
