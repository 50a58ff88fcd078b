#include "fieldvision/recon/trajectory_io.h"

#include <cmath>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv {

BallTrackFile ParseBallTrack(const CsvTable& t) {
  BallTrackFile out;
  std::string tc, xc, yc, zc;
  if (t.Has("time_s") || t.Has("x_m") || t.Has("frame")) {
    t.Require({"time_s", "x_m", "y_m", "z_m"});
    out.layout = "ball";
    tc = "time_s", xc = "x_m", yc = "y_m", zc = "z_m";
  } else if (t.Has("Timestamp")) {
    t.Require({"Timestamp", "X", "Y", "Z"});
    out.layout = "tt3d";
    tc = "Timestamp", xc = "X", yc = "Y", zc = "Z";
  } else {
    Throw(
        "ball track '{}': unknown columns (expected frame,time_s,x_m,y_m,z_m,n_cams,err_px "
        "or Timestamp,X,Y,Z)",
        t.name());
  }
  const bool has_frame = t.Has("frame"), has_n = t.Has("n_cams"), has_err = t.Has("err_px");
  int out_of_order = 0;
  for (size_t r = 0; r < t.rows(); ++r) {
    BallSample s;
    try {
      s.time_s = t.GetDouble(r, tc);
      s.ball_in_world = {t.GetDouble(r, xc), t.GetDouble(r, yc), t.GetDouble(r, zc)};
      if (has_frame) s.frame = t.GetInt(r, "frame");
      if (has_n) s.n_cams = static_cast<int>(t.GetInt(r, "n_cams"));
      if (has_err) s.err_px = t.GetDouble(r, "err_px");
    } catch (const Error& e) {
      out.skipped.push_back(fmt::format("{}; row skipped", e.what()));
      continue;
    }
    if (!std::isfinite(s.time_s) || !s.ball_in_world.allFinite()) {
      out.skipped.push_back(
          fmt::format("{}: NaN or infinite time or position; row skipped", t.Where(r)));
      continue;
    }
    if (!out.samples.empty() && s.time_s <= out.samples.back().time_s) {
      const bool dup = s.time_s == out.samples.back().time_s;
      out_of_order += !dup;
      out.skipped.push_back(fmt::format("{}: time {} s {} the previous row's {} s; row skipped",
                                        t.Where(r), s.time_s, dup ? "repeats" : "is before",
                                        out.samples.back().time_s));
      continue;
    }
    out.samples.push_back(s);
  }
  FV_REQUIRE(!out.samples.empty(), "ball track '{}': no valid rows ({} skipped)", t.name(),
             out.skipped.size());
  FV_REQUIRE(out_of_order <= static_cast<int>(out.samples.size()),
             "ball track '{}': times are not increasing ({} rows out of order); sort the file "
             "by time",
             t.name(), out_of_order);
  return out;
}

BallTrackFile ReadBallTrack(const std::string& path) {
  return ParseBallTrack(CsvTable::Read(path));
}

void WriteBallTrack(const std::string& path, const std::vector<BallSample>& samples) {
  CsvWriter w(path, {"frame", "time_s", "x_m", "y_m", "z_m", "n_cams", "err_px"});
  for (const auto& s : samples) {
    w << s.frame << s.time_s << s.ball_in_world.x() << s.ball_in_world.y() << s.ball_in_world.z()
      << s.n_cams << s.err_px;
    w.EndRow();
  }
  w.Close();
}

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
