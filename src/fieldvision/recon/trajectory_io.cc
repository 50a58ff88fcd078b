#include "fieldvision/recon/trajectory_io.h"

#include <cmath>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/strings.h"

namespace fv::recon {

namespace {

nlohmann::json SpinJson(const BallisticModel& m) {
  const double n = m.spin_radps.norm();
  const Eigen::Vector3d axis = n > 0 ? Eigen::Vector3d(m.spin_radps / n) : Eigen::Vector3d::Zero();
  return {{"rev_per_s", util::JsonRound(m.SpinRevPerS(), 2)},
          {"axis", util::JsonFromVector(axis, 3)},
          {"spin_radps", util::JsonFromVector(m.spin_radps, 2)},
          {"magnus_per_rad", util::JsonRound(m.magnus_per_rad, 7)}};
}

nlohmann::json FitJson(const BallisticFit& b) {
  if (!b.ok) return nullptr;
  nlohmann::json j = {{"rmse_m", util::JsonRound(b.rmse_m, 5)},
                      {"inliers", b.inliers},
                      {"samples", b.inlier.size()},
                      {"iterations", b.iterations},
                      {"parameters", b.parameters},
                      {"bic", util::JsonRound(b.bic, 2)},
                      {"drag_per_m", util::JsonRound(b.model.drag_per_m, 5)}};
  if (b.model.HasSpin()) j["spin"] = SpinJson(b.model);
  return j;
}

}  // namespace

nlohmann::json FlightToJson(const Flight& f) {
  nlohmann::json j;
  j["t_start_s"] = util::JsonRound(f.t_start_s, 4);
  j["t_end_s"] = util::JsonRound(f.t_end_s, 4);
  j["origin"] = util::JsonFromVector(f.origin_m, 4);
  j["landing"] = util::JsonFromVector(f.landing_m, 4);
  j["apex"] = util::JsonFromVector(f.apex_m, 4);
  j["v0_mps"] = util::JsonFromVector(f.v0_mps, 4);
  j["rmse_m"] = util::JsonRound(f.rmse_m, 5);
  j["index"] = f.index;
  j["start_event"] = FlightEventName(f.start_event);
  j["end_event"] = FlightEventName(f.end_event);
  j["t_landing_s"] = util::JsonRound(f.t_landing_s, 4);
  j["t_apex_s"] = util::JsonRound(f.t_apex_s, 4);
  j["origin_extrapolated"] = f.origin_extrapolated;
  j["landing_extrapolated"] = f.landing_extrapolated;
  j["t_first_seen_s"] = util::JsonRound(f.t_first_seen_s, 4);
  j["t_last_seen_s"] = util::JsonRound(f.t_last_seen_s, 4);
  j["speed_mps"] = util::JsonRound(f.speed_mps, 3);
  j["flight_time_s"] = util::JsonRound(f.FlightTime(), 4);
  j["model"] = FlightModelName(f.model_kind());
  j["drag_per_m"] = util::JsonRound(f.model().drag_per_m, 5);
  j["spin"] = f.spin_used ? SpinJson(f.model()) : nlohmann::json(nullptr);
  j["fit_no_drag"] = FitJson(f.no_drag);
  j["fit_drag"] = FitJson(f.with_drag);
  j["fit_spin"] = FitJson(f.with_spin);
  if (f.free_accel.ok) {
    j["fit_free_acceleration"] = {{"rmse_m", util::JsonRound(f.free_accel.rmse_m, 5)},
                                  {"accel_mps2", util::JsonFromVector(f.free_accel.accel_mps2, 3)}};
  }
  nlohmann::json seed;
  seed["method"] = "plane quadratic from the last 3 points, refined by least squares";
  seed["ok"] = f.seed.ok;
  if (f.seed.ok) {
    seed["origin"] = util::JsonFromVector(f.seed.origin_m, 4);
    seed["landing"] = util::JsonFromVector(f.seed.landing_m, 4);
    seed["apex"] = util::JsonFromVector(f.seed.apex_m, 4);
    seed["t_origin_s"] = util::JsonRound(f.seed.t_origin_s, 4);
    seed["t_landing_s"] = util::JsonRound(f.seed.t_landing_s, 4);
    seed["gravity_mps2"] = util::JsonRound(f.seed.gravity_mps2, 3);
    seed["landing_diff_m"] = util::JsonRound((f.seed.landing_m - f.landing_m).norm(), 4);
    seed["origin_diff_m"] = util::JsonRound((f.seed.origin_m - f.origin_m).norm(), 4);
  } else {
    seed["failure"] = f.seed.failure;
  }
  seed["rmse_m"] = util::JsonRound(f.seed.rmse_m, 5);
  j["seed"] = seed;
  return j;
}

nlohmann::json FlightsToJson(const TrajectoryResult& result, const TrajectoryOptions* options) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& f : result.flights) {
    nlohmann::json j = FlightToJson(f);
    if (f.end_event == FlightEvent::kBounce) {
      // What the bounce did (both arcs fitted) and what the bounce model predicts from this arc.
      for (const auto& b : result.breaks) {
        if (b.kind != FlightEvent::kBounce || std::abs(b.time_s - f.t_end_s) > 0.05) continue;
        if (!b.bounce.ok) break;
        j["bounce_measured"] = {
            {"restitution", util::JsonRound(b.bounce.restitution, 3)},
            {"friction", util::JsonRound(b.bounce.friction, 3)},
            {"spin_before_radps", util::JsonFromVector(b.bounce.spin_before_radps, 2)},
            {"spin_after_radps", util::JsonFromVector(b.bounce.spin_after_radps, 2)}};
        break;
      }
    }
    if (options != nullptr && !f.landing_extrapolated) {
      Eigen::Vector3d v = f.model().VelocityAt(f.t_landing_s), w = f.model().spin_radps;
      options->bounce.Apply(options->ball_radius_m, &v, &w);
      j["bounce_predicted"] = {{"restitution", options->bounce.restitution},
                               {"friction", options->bounce.friction},
                               {"v_after_mps", util::JsonFromVector(v, 3)},
                               {"spin_after_radps", util::JsonFromVector(w, 2)}};
    }
    a.push_back(j);
  }
  return a;
}

}  // namespace fv::recon
