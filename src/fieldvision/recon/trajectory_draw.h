// Pictures of ball flights so a user can judge the fit: a side view per flight (height over the
// horizontal distance along the flight, measured points, fitted arcs with and without drag, the
// seed's quadratic, origin, landing, apex and the landing predicted from the first half), a
// height-over-time view of the whole track with the breaks, and a top view on the field
// (field_draw.h) with the landing calls.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/field/field.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/recon/trajectory.h"
#include "fieldvision/recon/trajectory_decisions.h"
#include "fieldvision/recon/trajectory_predict.h"

namespace fv::recon {

cv::Mat DrawFlightSide(const std::vector<BallSample>& track, const TrajectoryResult& result,
                       const Flight& flight, const TrajectoryOptions& options,
                       const LandingPrediction* prediction, cv::Size size = {1100, 550});

cv::Mat DrawTrackHeight(const std::vector<BallSample>& track, const TrajectoryResult& result,
                        const TrajectoryOptions& options, cv::Size size = {1600, 600});

// field may be null (a plain grid around the track). Axes in metres, scale bar, legend; the
// extrapolated parts of flights thin and their origins and landings hollow.
cv::Mat DrawFlightsTop(const std::vector<BallSample>& track, const TrajectoryResult& result,
                       const field::FieldModel* field, const Decisions* decisions,
                       int width_px = 1400);

// The field turned a quarter turn (x -> y): for tracks recorded with the length along y (TT3D).
field::FieldModel RotateFieldQuarter(const field::FieldModel& field);

}  // namespace fv::recon
