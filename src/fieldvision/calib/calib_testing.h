// Helpers shared by the calibration tests (header only, not part of the library): clicks of a
// field's keypoints as a user would make them, and cameras of the synthetic presets.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "fieldvision/calib/extrinsics.h"
#include "fieldvision/field/field.h"
#include "fieldvision/synth/synth.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/stats.h"

namespace fv::calib::test_util {

// The field's ground keypoints that the camera sees, 8 of them spread over the list.
inline std::vector<PointCorrespondence> ClickKeypoints(const camera::Camera& cam,
                                                       const field::FieldModel& field, int count,
                                                       double noise_px, util::Rng& rng) {
  std::vector<const field::FieldKeypoint*> seen;
  for (const auto& k : field.keypoints) {
    const auto uv = cam.Project(k.position_m);
    if (k.position_m.z() == 0.0 && uv && cam.InImage(*uv, 10)) seen.push_back(&k);
  }
  // Farthest-point order in the image, from the first seen point: what a user told to click
  // points spread over the image does.
  std::vector<PointCorrespondence> pts;
  std::vector<bool> taken(seen.size(), false);
  for (int i = 0; i < count && i < static_cast<int>(seen.size()); ++i) {
    size_t pick = 0;
    double best = -1;
    for (size_t j = 0; j < seen.size(); ++j) {
      if (taken[j]) continue;
      double nearest = 1e18;
      for (const auto& p : pts) {
        nearest = std::min(
            nearest, (*cam.Project(seen[j]->position_m) - *cam.Project(p.p_world)).squaredNorm());
      }
      if (nearest > best) {
        best = nearest;
        pick = j;
      }
    }
    taken[pick] = true;
    const field::FieldKeypoint* k = seen[pick];
    PointCorrespondence p;
    p.name = k->name;
    p.p_world = k->position_m;
    p.uv_px = *cam.Project(k->position_m) +
              Eigen::Vector2d(rng.Normal(0, noise_px), rng.Normal(0, noise_px));
    pts.push_back(p);
  }
  return pts;
}

// The cameras of a synth preset (position, look-at and field of view as the renderer builds
// them), without rendering anything.
inline std::vector<camera::Camera> PresetCameras(const std::string& preset, uint64_t seed) {
  const synth::SceneSpec spec = synth::Preset(preset, seed);
  std::vector<camera::Camera> cams;
  for (const auto& s : spec.cameras) {
    camera::Camera c = camera::Camera::FromFov(s.width, s.height, s.hfov_deg);
    if (s.fx > 0) c.fx = s.fx;
    if (s.fy > 0) c.fy = s.fy;
    c.distortion = s.distortion;
    c.name = s.name;
    c.has_pose = true;
    c.cam_from_world = s.has_rvec_tvec ? geometry::Rigid3d::FromRvecTvec(s.rvec, s.tvec)
                                       : geometry::Rigid3d::LookAt(s.position_m, s.look_at_m);
    cams.push_back(c);
  }
  return cams;
}

// The rig as `calibrate multi` gives it: poses in the first camera's frame.
inline std::vector<camera::Camera> InRigFrame(const std::vector<camera::Camera>& world) {
  std::vector<camera::Camera> rig = world;
  const geometry::Rigid3d world_from_ref = world[0].cam_from_world.Inverse();
  for (auto& c : rig) c.cam_from_world = c.cam_from_world * world_from_ref;
  return rig;
}

// The largest camera centre difference between two placements of one rig.
inline double WorstCentreErrorM(const std::vector<camera::Camera>& a,
                                const std::vector<camera::Camera>& b) {
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, (a[i].CentreInWorld() - b[i].CentreInWorld()).norm());
  }
  return worst;
}

// Where a placement puts the field: the distance between a point of the playing area (a 1 m
// grid at heights 0 and 1 m) and where placement `a` puts it when truth `b` is right (the same
// camera coordinates: x_a = A0^-1 B0 x). Returns the median; *max the largest.
inline double FieldPositionErrorM(const std::vector<camera::Camera>& a,
                                  const std::vector<camera::Camera>& b,
                                  const field::FieldModel& field, double* max) {
  const geometry::Rigid3d a_from_b = a[0].cam_from_world.Inverse() * b[0].cam_from_world;
  std::vector<double> err;
  for (double x = -0.5 * field.length_m; x <= 0.5 * field.length_m + 1e-9; x += 1.0) {
    for (double y = -0.5 * field.width_m; y <= 0.5 * field.width_m + 1e-9; y += 1.0) {
      for (double z : {0.0, 1.0}) {
        const Eigen::Vector3d p(x, y, z);
        err.push_back((a_from_b * p - p).norm());
      }
    }
  }
  *max = *std::max_element(err.begin(), err.end());
  return util::NearestRankPercentile(err, 0.5);
}

}  // namespace fv::calib::test_util
