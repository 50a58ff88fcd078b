#include "fieldvision/recon/trajectory_io.h"

#include <cmath>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv {

nlohmann::json Vec3Json(const Eigen::Vector3d& v, int decimals) {
  const double f = std::pow(10.0, decimals);
  return nlohmann::json::array(
      {std::round(v.x() * f) / f, std::round(v.y() * f) / f, std::round(v.z() * f) / f});
}

namespace {

double Round(double v, int decimals = 4) {
  const double f = std::pow(10.0, decimals);
  return std::round(v * f) / f;
}

nlohmann::json SpinJson(const BallisticModel& m) {
  const double n = m.spin_radps.norm();
  const Eigen::Vector3d axis = n > 0 ? Eigen::Vector3d(m.spin_radps / n) : Eigen::Vector3d::Zero();
  return {{"rev_per_s", Round(m.SpinRevPerS(), 2)},
          {"axis", Vec3Json(axis, 3)},
          {"spin_radps", Vec3Json(m.spin_radps, 2)},
          {"magnus_per_rad", Round(m.magnus_per_rad, 7)}};
}

nlohmann::json FitJson(const BallisticFit& b) {
  if (!b.ok) return nullptr;
  nlohmann::json j = {{"rmse_m", Round(b.rmse_m, 5)},
                      {"inliers", b.inliers},
                      {"samples", b.inlier.size()},
                      {"iterations", b.iterations},
                      {"parameters", b.parameters},
                      {"bic", Round(b.bic, 2)},
                      {"drag_per_m", Round(b.model.drag_per_m, 5)}};
  if (b.model.HasSpin()) j["spin"] = SpinJson(b.model);
  return j;
}

}  // namespace

nlohmann::json FlightToJson(const Flight& f) {
  nlohmann::json j;
  j["t_start_s"] = Round(f.t_start_s);
  j["t_end_s"] = Round(f.t_end_s);
  j["origin"] = Vec3Json(f.origin_m);
  j["landing"] = Vec3Json(f.landing_m);
  j["apex"] = Vec3Json(f.apex_m);
  j["v0_mps"] = Vec3Json(f.v0_mps);
  j["rmse_m"] = Round(f.rmse_m, 5);
  j["index"] = f.index;
  j["start_event"] = FlightEventName(f.start_event);
  j["end_event"] = FlightEventName(f.end_event);
  j["t_landing_s"] = Round(f.t_landing_s);
  j["t_apex_s"] = Round(f.t_apex_s);
  j["origin_extrapolated"] = f.origin_extrapolated;
  j["landing_extrapolated"] = f.landing_extrapolated;
  j["t_first_seen_s"] = Round(f.t_first_seen_s);
  j["t_last_seen_s"] = Round(f.t_last_seen_s);
  j["speed_mps"] = Round(f.speed_mps, 3);
  j["flight_time_s"] = Round(f.FlightTime());
  j["model"] = FlightModelName(f.model_kind());
  j["drag_per_m"] = Round(f.model().drag_per_m, 5);
  j["spin"] = f.spin_used ? SpinJson(f.model()) : nlohmann::json(nullptr);
  j["fit_no_drag"] = FitJson(f.no_drag);
  j["fit_drag"] = FitJson(f.with_drag);
  j["fit_spin"] = FitJson(f.with_spin);
  if (f.free_accel.ok) {
    j["fit_free_acceleration"] = {{"rmse_m", Round(f.free_accel.rmse_m, 5)},
                                  {"accel_mps2", Vec3Json(f.free_accel.accel_mps2, 3)}};
  }
  nlohmann::json seed;
  seed["method"] = "plane quadratic from the last 3 points, refined by least squares";
  seed["ok"] = f.seed.ok;
  if (f.seed.ok) {
    seed["origin"] = Vec3Json(f.seed.origin_m);
    seed["landing"] = Vec3Json(f.seed.landing_m);
    seed["apex"] = Vec3Json(f.seed.apex_m);
    seed["t_origin_s"] = Round(f.seed.t_origin_s);
    seed["t_landing_s"] = Round(f.seed.t_landing_s);
    seed["gravity_mps2"] = Round(f.seed.gravity_mps2, 3);
    seed["landing_diff_m"] = Round((f.seed.landing_m - f.landing_m).norm());
    seed["origin_diff_m"] = Round((f.seed.origin_m - f.origin_m).norm());
  } else {
    seed["failure"] = f.seed.failure;
  }
  seed["rmse_m"] = Round(f.seed.rmse_m, 5);
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
        j["bounce_measured"] = {{"restitution", Round(b.bounce.restitution, 3)},
                                {"friction", Round(b.bounce.friction, 3)},
                                {"spin_before_radps", Vec3Json(b.bounce.spin_before_radps, 2)},
                                {"spin_after_radps", Vec3Json(b.bounce.spin_after_radps, 2)}};
        break;
      }
    }
    if (options != nullptr && !f.landing_extrapolated) {
      Eigen::Vector3d v = f.model().VelocityAt(f.t_landing_s), w = f.model().spin_radps;
      options->bounce.Apply(options->ball_radius_m, &v, &w);
      j["bounce_predicted"] = {{"restitution", options->bounce.restitution},
                               {"friction", options->bounce.friction},
                               {"v_after_mps", Vec3Json(v, 3)},
                               {"spin_after_radps", Vec3Json(w, 2)}};
    }
    a.push_back(j);
  }
  return a;
}

}  // namespace fv
