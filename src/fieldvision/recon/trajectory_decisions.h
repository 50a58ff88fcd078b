// Referee calls from fitted ball flights on a field model: in/out of each landing against the
// playing area (football: out when the whole ball is beyond the outer edge of the line, IFAB Law
// 9; tennis: in when the ball touches the line, ITF Rule 12; basketball: out when it touches the
// line, FIBA Art. 23) or a named line; goal-line crossings (whole ball beyond the goal line
// between the posts and under the bar, IFAB Law 10); made basketball shots (centre passes down
// through the ring). The ball path is the fitted arc inside flights and the samples between them.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "fieldvision/field/field.h"
#include "fieldvision/recon/trajectory.h"

namespace fv::recon {

struct DecisionOptions {
  std::string rule = "auto";       // auto (from the field's name), football, tennis, basketball
  std::vector<std::string> lines;  // named field lines to judge each landing against too
  double contact_patch_m = 0.02;   // radius of the ball's contact with the ground (tennis, FIBA)
  double time_step_s = 0.001;      // scan step for crossings
  void Check() const;
};

// In/out of one landing. margin_m > 0: in by that much; < 0: out by that much.
struct LandingCall {
  int flight = -1;
  double time_s = 0.0;
  Eigen::Vector2d point_m = Eigen::Vector2d::Zero();  // ball centre above the contact
  bool extrapolated = false;  // where the arc would have landed (hit or end of track)
  std::string against;        // "playing area" or a line's name
  bool in = false;            // playing area: in; named line: the ball touches the line
  double margin_m = 0.0;
};

struct GoalCrossing {
  int flight = -1;  // -1: between flights (rolling)
  std::string goal;
  double time_s = 0.0;
  Eigen::Vector3d ball_in_world = Eigen::Vector3d::Zero();
};

struct MadeShot {
  int flight = -1;
  std::string hoop;
  double time_s = 0.0;
  double offset_m = 0.0;  // horizontal distance of the centre from the ring's centre
  bool clean = false;     // passed without touching the ring
};

struct TimelineEvent {
  double time_s = 0.0;
  std::string text;
  // The flight it is about, for the order of events at one time (a landing before the bounce's
  // next flight); events of no one flight after those of flights.
  int flight = std::numeric_limits<int>::max();
};

struct Decisions {
  std::string rule;
  std::vector<LandingCall> landings;
  std::vector<GoalCrossing> goals;
  std::vector<MadeShot> shots;
  std::vector<TimelineEvent> timeline;  // kicks, bounces, hits, calls; in time order
  nlohmann::json ToJson() const;
};

// The ball position at time_s: the fitted arc inside a flight, else linear between samples.
Eigen::Vector3d BallPathAt(const std::vector<BallSample>& track, const TrajectoryResult& result,
                           double time_s, int* flight = nullptr);

// Calls for a track; with an empty field (no length) only the timeline of kicks and bounces.
Decisions MakeDecisions(const std::vector<BallSample>& track, const TrajectoryResult& result,
                        const field::FieldModel* field, const TrajectoryOptions& options,
                        const DecisionOptions& decision_options);

}  // namespace fv::recon
