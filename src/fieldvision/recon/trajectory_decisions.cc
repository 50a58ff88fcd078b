#include "fieldvision/recon/trajectory_decisions.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::recon {
namespace {

// Signed distance of p to the rectangle |x| <= hx, |y| <= hy: > 0 inside.
double InsideDistance(const Eigen::Vector2d& p, double hx, double hy) {
  const double dx = std::abs(p.x()) - hx, dy = std::abs(p.y()) - hy;
  if (dx <= 0 && dy <= 0) return -std::max(dx, dy);
  return -std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
}

double R4(double v) { return std::round(v * 1e4) / 1e4; }

}  // namespace

void DecisionOptions::Check() const {
  FV_REQUIRE(rule == "auto" || rule == "football" || rule == "tennis" || rule == "basketball",
             "decision rule must be auto, football, tennis or basketball (got '{}')", rule);
  CheckNonNegative(contact_patch_m, "contact_patch_m");
  CheckInRange(time_step_s, 1e-5, 0.1, "time_step_s");
}

Eigen::Vector3d BallPathAt(const std::vector<BallSample>& track, const TrajectoryResult& result,
                           double time_s, int* flight) {
  for (const auto& f : result.flights) {
    if (time_s >= f.t_start_s && time_s <= f.t_end_s) {
      if (flight) *flight = f.index;
      return f.model().PositionAt(time_s);
    }
  }
  if (flight) *flight = -1;
  // Linear between the nearest non-outlier samples.
  int before = -1, after = -1;
  for (int i = 0; i < static_cast<int>(track.size()); ++i) {
    if (result.outlier.size() == track.size() && result.outlier[i]) continue;
    if (track[i].time_s <= time_s) before = i;
    if (track[i].time_s >= time_s) {
      after = i;
      break;
    }
  }
  if (before < 0) return after < 0 ? Eigen::Vector3d::Zero() : track[after].ball_in_world;
  if (after < 0 || after == before) return track[before].ball_in_world;
  const double f = (time_s - track[before].time_s) / (track[after].time_s - track[before].time_s);
  return (1 - f) * track[before].ball_in_world + f * track[after].ball_in_world;
}

namespace {

// BallPathAt for times that only increase (the crossing scan): the same answer in amortised
// O(log flights) per call instead of a pass over every flight and sample.
class BallPathCursor {
 public:
  BallPathCursor(const std::vector<BallSample>& track, const TrajectoryResult& result)
      : track_(track), result_(result) {
    by_start_.resize(result.flights.size());
    std::iota(by_start_.begin(), by_start_.end(), 0);
    std::stable_sort(by_start_.begin(), by_start_.end(), [&](int a, int b) {
      return result.flights[a].t_start_s < result.flights[b].t_start_s;
    });
  }

  Eigen::Vector3d At(double time_s, int* flight) {
    // The first flight (in the result's order) whose [t_start_s, t_end_s] holds the time: flights
    // join `active_` when they start; one that has ended is dropped when it comes first.
    const auto& flights = result_.flights;
    while (next_start_ < by_start_.size() && flights[by_start_[next_start_]].t_start_s <= time_s) {
      active_.insert(by_start_[next_start_++]);
    }
    while (!active_.empty() && flights[*active_.begin()].t_end_s < time_s) {
      active_.erase(active_.begin());
    }
    if (!active_.empty()) {
      const Flight& f = flights[*active_.begin()];
      if (flight) *flight = f.index;
      return ModelAt(*active_.begin(), time_s);
    }
    if (flight) *flight = -1;
    // Linear between the nearest non-outlier samples (as BallPathAt).
    const int n = static_cast<int>(track_.size());
    auto outlier = [&](int i) {
      return result_.outlier.size() == track_.size() && result_.outlier[i];
    };
    while (k_ < n && (outlier(k_) || track_[k_].time_s < time_s)) {
      if (!outlier(k_)) last_before_ = k_;
      ++k_;
    }
    int before = last_before_;
    const int after = k_ < n ? k_ : -1;
    if (after >= 0 && track_[after].time_s <= time_s) before = after;
    if (before < 0) return after < 0 ? Eigen::Vector3d::Zero() : track_[after].ball_in_world;
    if (after < 0 || after == before) return track_[before].ball_in_world;
    const double f =
        (time_s - track_[before].time_s) / (track_[after].time_s - track_[before].time_s);
    return (1 - f) * track_[before].ball_in_world + f * track_[after].ball_in_world;
  }

 private:
  // The flight's position: a drag or spin model is walked on from the time asked before (one
  // integration from the model's reference time per call cost O(flight time) each).
  Eigen::Vector3d ModelAt(int i, double time_s) {
    const BallisticModel& m = result_.flights[i].model();
    if (m.Parabola()) return m.PositionAt(time_s);
    if (walk_flight_ != i || time_s < walk_t_s_) {
      m.StateAt(time_s, &walk_p_, &walk_v_);
      walk_flight_ = i;
    } else {
      m.Advance(time_s - walk_t_s_, &walk_p_, &walk_v_);
    }
    walk_t_s_ = time_s;
    return walk_p_;
  }

  const std::vector<BallSample>& track_;
  const TrajectoryResult& result_;
  int walk_flight_ = -1;
  double walk_t_s_ = 0.0;
  Eigen::Vector3d walk_p_, walk_v_;
  std::vector<int> by_start_;
  size_t next_start_ = 0;
  std::set<int> active_;
  int k_ = 0;             // the first non-outlier sample at or after the last time asked
  int last_before_ = -1;  // the last non-outlier sample before it
};

}  // namespace

namespace {

// The timeline's line for each flight: how it started (where it was first seen when the origin
// is extrapolated) and any hit that ends it.
void AddFlightEvents(const TrajectoryResult& result, std::vector<TimelineEvent>* timeline) {
  for (const auto& f : result.flights) {
    std::string what;
    switch (f.start_event) {
      case FlightEvent::kBounce:
        what = "bounce";
        break;
      case FlightEvent::kHit:
        what = "hit/kick in the air";
        break;
      case FlightEvent::kGround:
        what = "kick/hit from the ground";
        break;
      default:
        what = "flight already under way";
    }
    if (f.origin_extrapolated) {
      // Not seen: say where the flight was first seen, and that the origin is the model's.
      const Eigen::Vector3d p = f.model().PositionAt(f.t_first_seen_s);
      timeline->push_back(
          {f.t_first_seen_s,
           fmt::format("flight {}: {}, first seen at ({:.2f}, {:.2f}, {:.2f}) m, {:.1f} m/s, apex "
                       "{:.2f} m; origin not seen (extrapolated {:.2f} s back to ({:.2f}, {:.2f}, "
                       "{:.2f}) m)",
                       f.index, what, p.x(), p.y(), p.z(),
                       f.model().VelocityAt(f.t_first_seen_s).norm(), f.apex_m.z(),
                       f.t_first_seen_s - f.t_start_s, f.origin_m.x(), f.origin_m.y(),
                       f.origin_m.z()),
           f.index});
    } else {
      timeline->push_back({f.t_start_s,
                           fmt::format("flight {}: {} at ({:.2f}, {:.2f}, {:.2f}) m, {:.1f} m/s, "
                                       "apex {:.2f} m, flight time {:.2f} s",
                                       f.index, what, f.origin_m.x(), f.origin_m.y(),
                                       f.origin_m.z(), f.speed_mps, f.apex_m.z(), f.FlightTime()),
                           f.index});
    }
    if (f.end_event == FlightEvent::kHit) {
      timeline->push_back(
          {f.t_end_s,
           fmt::format("flight {}: hit at ({:.2f}, {:.2f}, {:.2f}) m", f.index,
                       f.model().PositionAt(f.t_end_s).x(), f.model().PositionAt(f.t_end_s).y(),
                       f.model().PositionAt(f.t_end_s).z()),
           f.index});
    }
  }
}

// "auto": tennis or basketball when the field's name says so, else football.
std::string ResolveRule(const std::string& rule, const field::FieldModel& field) {
  if (rule != "auto") return rule;
  const std::string n = util::ToLower(field.name);
  return n.find("tennis") != std::string::npos       ? "tennis"
         : n.find("basketball") != std::string::npos ? "basketball"
                                                     : "football";
}

// In/out of each landing against the playing area under `rule`, and touches of each named line.
std::vector<LandingCall> CallLandings(const TrajectoryResult& result,
                                      const field::FieldModel& field, const std::string& rule,
                                      double r, const DecisionOptions& d) {
  std::vector<LandingCall> landings;
  for (const auto& f : result.flights) {
    LandingCall c;
    c.flight = f.index;
    c.time_s = f.t_landing_s;
    c.point_m = f.landing_m.head<2>();
    c.extrapolated = f.landing_extrapolated;
    c.against = "playing area";
    const double din = InsideDistance(c.point_m, 0.5 * field.length_m, 0.5 * field.width_m);
    // football: any part of the ball's projection over the area or its lines; tennis: the
    // contact patch touches the area (lines are in); basketball: the patch clear of the lines
    // (the area's edge is the lines' inner edge).
    c.margin_m = rule == "football" ? din + r
                 : rule == "tennis" ? din + d.contact_patch_m
                                    : din - d.contact_patch_m;
    c.in = c.margin_m >= 0;
    landings.push_back(c);
    for (const auto& name : d.lines) {
      double gap = 1e9;
      for (const auto& s : field.segments) {
        if (s.name != name) continue;
        gap = std::min(gap, field::DistanceToSegment(c.point_m, s.a, s.b) - 0.5 * s.width_m);
      }
      LandingCall lc = c;
      lc.against = name;
      const double patch = rule == "football" ? r : d.contact_patch_m;
      lc.margin_m = patch - gap;  // > 0: the ball touches the line
      lc.in = lc.margin_m >= 0;
      landings.push_back(lc);
    }
  }
  return landings;
}

// Walks the ball's path in time steps: goal-line crossings (the whole ball beyond the line between
// the posts and under the bar) and shots down through a hoop.
void ScanGoalsAndShots(const std::vector<BallSample>& track, const TrajectoryResult& result,
                       const field::FieldModel& field, double r, const DecisionOptions& d,
                       Decisions* out) {
  // Scan the ball's path for goal-line crossings and made shots.
  if (!track.empty() && (!field.goals.empty() || !field.hoops.empty())) {
    const double t0 = track.front().time_s, t1 = track.back().time_s;
    BallPathCursor path(track, result);
    Eigen::Vector3d prev = path.At(t0, nullptr);
    // Whether the whole ball is beyond each goal's line: a goal is the ball passing from in
    // front of it to beyond it inside the goal mouth (where it crosses: between the posts, under
    // the bar). A ball over the bar and then behind the line, or one that never was in front of
    // it, is none.
    const auto beyond = [&](const field::FieldGoal& goal, const Eigen::Vector3d& p) {
      return goal.side * (p.x() - goal.line_x_m) > 0.5 * field.line_width_m + r;
    };
    std::vector<bool> was_beyond;
    for (const auto& goal : field.goals) {
      was_beyond.push_back(beyond(goal, prev));
      if (was_beyond.back() && prev.y() >= goal.y_min_m && prev.y() <= goal.y_max_m &&
          prev.z() <= goal.height_m) {
        out->timeline.push_back(
            {t0, fmt::format("the ball is already in {} when the track starts: its crossing of "
                             "the line is not seen, no goal called",
                             goal.name)});
      }
    }
    for (double t = t0 + d.time_step_s; t <= t1; t += d.time_step_s) {
      int fl = -1;
      const Eigen::Vector3d p = path.At(t, &fl);
      for (size_t g = 0; g < field.goals.size(); ++g) {
        const field::FieldGoal& goal = field.goals[g];
        const bool now_beyond = beyond(goal, p);
        if (now_beyond && !was_beyond[g] && p.x() != prev.x()) {
          // Where the ball's path meets the plane its whole ball is beyond from.
          const double x_c = goal.line_x_m + goal.side * (0.5 * field.line_width_m + r);
          const double f = std::clamp((x_c - prev.x()) / (p.x() - prev.x()), 0.0, 1.0);
          const Eigen::Vector3d c = prev + f * (p - prev);
          if (c.y() >= goal.y_min_m && c.y() <= goal.y_max_m && c.z() <= goal.height_m &&
              c.z() >= -r) {
            out->goals.push_back({fl, goal.name, t, c});
            out->timeline.push_back(
                {t, fmt::format("GOAL: the whole ball crossed the line of {} at ({:.2f}, {:.2f}, "
                                "{:.2f}) m",
                                goal.name, c.x(), c.y(), c.z())});
          }
        }
        was_beyond[g] = now_beyond;
      }
      for (const auto& h : field.hoops) {
        const double hz = h.centre_m.z();
        if (prev.z() > hz && p.z() <= hz) {
          const double f = (prev.z() - hz) / (prev.z() - p.z());
          const Eigen::Vector3d c = prev + f * (p - prev);
          const double off = (c.head<2>() - h.centre_m.head<2>()).norm();
          if (off < h.radius_m) {
            out->shots.push_back({fl, h.name, t, off, off < h.radius_m - r});
            out->timeline.push_back(
                {t, fmt::format("MADE SHOT through {} ({} {:.3f} m from the centre)", h.name,
                                off < h.radius_m - r ? "clean," : "touching the ring,", off)});
          }
        }
      }
      prev = p;
    }
  }
}

}  // namespace

Decisions MakeDecisions(const std::vector<BallSample>& track, const TrajectoryResult& result,
                        const field::FieldModel* field, const TrajectoryOptions& o,
                        const DecisionOptions& d) {
  d.Check();
  Decisions out;
  const double r = o.ball_radius_m;
  AddFlightEvents(result, &out.timeline);
  if (field && field->length_m > 0) {
    const std::string rule = ResolveRule(d.rule, *field);
    out.rule = rule;
    for (const auto& name : d.lines) {
      bool found = false;
      for (const auto& s : field->segments) found |= s.name == name;
      FV_REQUIRE(found, "field '{}' has no line named '{}' (see `fieldvision field show {}`)",
                 field->name, name, field->name);
    }
    out.landings = CallLandings(result, *field, rule, r, d);
    for (const auto& c : out.landings) {
      out.timeline.push_back(
          {c.time_s,
           fmt::format("flight {}: {} at ({:.2f}, {:.2f}) m: {} {} by {:.3f} m", c.flight,
                       c.extrapolated ? "would land" : "lands", c.point_m.x(), c.point_m.y(),
                       c.against == "playing area" ? (c.in ? "IN" : "OUT")
                                                   : (c.in ? "TOUCHES" : "CLEAR OF"),
                       c.against, std::abs(c.margin_m)),
           c.flight});
    }
    ScanGoalsAndShots(track, result, *field, r, d, &out);
  }
  std::stable_sort(out.timeline.begin(), out.timeline.end(),
                   [](const TimelineEvent& a, const TimelineEvent& b) {
                     return a.time_s != b.time_s ? a.time_s < b.time_s : a.flight < b.flight;
                   });
  return out;
}

nlohmann::json Decisions::ToJson() const {
  nlohmann::json j;
  j["rule"] = rule;
  j["landings"] = nlohmann::json::array();
  for (const auto& c : landings) {
    j["landings"].push_back({{"flight", c.flight},
                             {"time_s", R4(c.time_s)},
                             {"point", {R4(c.point_m.x()), R4(c.point_m.y())}},
                             {"extrapolated", c.extrapolated},
                             {"against", c.against},
                             {c.against == "playing area" ? "in" : "touches", c.in},
                             {"margin_m", R4(c.margin_m)}});
  }
  j["goal_crossings"] = nlohmann::json::array();
  for (const auto& g : goals) {
    j["goal_crossings"].push_back(
        {{"flight", g.flight},
         {"goal", g.goal},
         {"time_s", R4(g.time_s)},
         {"ball", {R4(g.ball_in_world.x()), R4(g.ball_in_world.y()), R4(g.ball_in_world.z())}}});
  }
  j["made_shots"] = nlohmann::json::array();
  for (const auto& s : shots) {
    j["made_shots"].push_back({{"flight", s.flight},
                               {"hoop", s.hoop},
                               {"time_s", R4(s.time_s)},
                               {"offset_m", R4(s.offset_m)},
                               {"clean", s.clean}});
  }
  j["timeline"] = nlohmann::json::array();
  for (const auto& e : timeline) {
    j["timeline"].push_back({{"time_s", R4(e.time_s)}, {"event", e.text}});
  }
  return j;
}

}  // namespace fv::recon
