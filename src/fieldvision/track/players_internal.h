// The stages of RunPlayers and StitchTracklets (players.h), for tests.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/track/bytetrack.h"
#include "fieldvision/track/camera_motion.h"
#include "fieldvision/track/players.h"

namespace fv::track {

// The feature filter of a camera that moves (CameraMotion::SetFeatureFilter): a place on the
// first view (undistorted pixels, homogeneous through a frame's view) is kept where the frame's
// ray meets the ground ahead of it within the field and its surround, less 0.3 m.
CameraMotion::FeatureFilter OnTheGround(const camera::Camera& first,
                                        const field::FieldModel& field);

// One track's ends as the stitcher sees them: ground positions (metres) and velocities (m/s).
struct Tracklet {
  int id = 0;
  std::vector<const TrackRow*> rows;             // by frame
  Eigen::Vector2d first, last, v_first, v_last;  // metres, metres per second
  int first_frame = 0, last_frame = 0;           // frames of `first` and `last`
  bool starts_at_border = false, ends_at_border = false;
};

// The rows of each id with their ends: within velocity_window_s of the first and last row; a box
// much shorter than the person there is partly hidden (its foot taken at the person's height below
// its top, or the box left out). Positions are the field positions when every row has one, else
// foot pixels scaled by box height; lengthened boxes are mapped through `camera` when posed.
std::map<int, Tracklet> BuildTracklets(const std::vector<TrackRow>& rows, const StitchOptions& o,
                                       double fps, cv::Size image, const StitchCamera& camera = {});

struct TrackletLink {
  double cost;
  int a, b;  // a ends before b starts
};

// Every allowed join (gap, reach across the gap, torso colour), cheapest first.
std::vector<TrackletLink> TrackletLinks(const std::map<int, Tracklet>& tracklets,
                                        const std::map<int, TrackAppearance>& appearance,
                                        const StitchOptions& o, double fps);

// Takes links greedily (one successor and one predecessor per tracklet) and renames every row to
// the first tracklet of its chain; returns the joins made.
int JoinTracklets(const std::vector<TrackletLink>& links, std::vector<TrackRow>& rows);

// Whether a foot point lies on the ground within the field (and margin) when a field is given.
FootFilter FieldFootFilter(const camera::Camera& camera, const field::FieldModel* field,
                           double margin_m);

// Adds the torso histograms of confident, unpredicted tracks that no other track overlaps.
void AddTrackAppearance(const std::vector<TrackState>& states, const cv::Mat& frame,
                        double high_score, std::map<int, TrackAppearance>& appearance);

// Mean CIELAB colour of the torso (lightness weighted 0.3: chroma first); nullopt when tiny.
std::optional<cv::Vec3f> TorsoColour(const cv::Mat& frame, const cv::Rect2d& box);

// Removes the rows of ids with fewer than min_frames rows; returns how many ids went.
int DropShortTracks(std::vector<TrackRow>& rows, int min_frames);

// Two teams by k-means of the tracks' mean torso colours (ids in `ids` only): id -> 0 or 1.
std::map<int, int> AssignTeams(const std::map<int, std::vector<cv::Vec3f>>& torso_colours,
                               const std::set<int>& ids);

}  // namespace fv::track
