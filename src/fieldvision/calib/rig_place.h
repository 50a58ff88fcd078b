// Placing a calibrated rig (cameras with poses in a common frame, e.g. `calibrate multi`'s, whose
// frame is the first camera's) on the field: one rigid transform ref_from_world from field points
// clicked in any of its cameras, the cameras' relative poses kept. Starts: each camera with 4 or
// more points alone (RANSAC PnP, extrinsics.h), a linear generalized PnP over all points (the
// ray constraints of every camera stacked, as in the DLT; planar points drop the third rotation
// column) and rotations sampled over SO(3), each with its least-squares translation (linear for a
// given rotation); every start is refined by Ceres (Huber loss), the one that fits the most points
// wins, and points far off are then left out and the fit repeated.
// Also: carrying a rig when one camera's pose changes (the others follow rigidly).
#pragma once

#include <string>
#include <vector>

#include "fieldvision/calib/extrinsics.h"
#include "fieldvision/camera/camera.h"

namespace fv::calib {

struct RigPlacementOptions {
  ExtrinsicsOptions pnp;    // starts from single cameras
  double huber_px = 2.0;    // robust loss scale
  double outlier_px = 8.0;  // points farther off after the fit are left out (then refitted)
  int max_iterations = 100;
  int min_points = 4;  // over all cameras
  void Check() const;
};

struct RigPlacementResult {
  std::vector<camera::Camera> cameras;  // the rig with world poses (cam_from_world)
  geometry::Rigid3d ref_from_world;     // the rig's frame in the world
  // Per camera, the residuals of its points (empty for cameras without points).
  std::vector<std::vector<PointResidual>> points;
  std::vector<double> rms_px;  // per camera over its inliers (0 without points)
  double rms_px_all = 0.0;
  int num_points = 0, num_inliers = 0;
  std::string start;  // which start won ("camera cam2", "all cameras (linear)")
  int iterations = 0;
  std::string Summary() const;
};

// rig[i] has a pose in the rig's frame; points[i] are camera i's clicks (may be empty). Throws
// fv::Error when the points cannot place the rig (too few, on one line, no start fits).
RigPlacementResult PlaceRig(const std::vector<camera::Camera>& rig,
                            const std::vector<std::vector<PointCorrespondence>>& points,
                            const RigPlacementOptions& options = {});

// The rig moved so that camera k has the pose cam_k_from_world; the relative poses are kept.
std::vector<camera::Camera> CarryRig(const std::vector<camera::Camera>& rig, int k,
                                     const geometry::Rigid3d& cam_k_from_world);

}  // namespace fv::calib
