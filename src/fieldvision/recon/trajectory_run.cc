#include "fieldvision/recon/trajectory_run.h"

#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "fieldvision/recon/trajectory_draw.h"
#include "fieldvision/util/error.h"

namespace fv {

void TrajectoryJob::Check() const {
  FV_REQUIRE(!in_path.empty(), "trajectory: --in is required");
  FV_REQUIRE(!out_path.empty(), "trajectory: --out is required");
  CheckNonNegative(ball_diameter_m, "ball_diameter_m");
  CheckNonNegative(accel_slack_mps2, "accel_slack_mps2");
  CheckInRange(predict_fraction, 0.05, 1.0, "predict_fraction");
  decisions.Check();
  smoother.Check();
}

TrajectoryJobResult RunTrajectory(const TrajectoryJob& job, std::ostream& log) {
  job.Check();
  for (const std::string* p : {&job.out_path, &job.report_path, &job.smoothed_path}) {
    const auto parent = std::filesystem::path(*p).parent_path();
    if (p->empty() || parent.empty()) continue;
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    FV_REQUIRE(!ec, "cannot create folder '{}' for '{}': {}", parent.string(), *p, ec.message());
  }
  TrajectoryJobResult out;
  out.input = ReadBallTrack(job.in_path);
  const auto& track = out.input.samples;
  const size_t max_listed = 10;
  for (size_t i = 0; i < out.input.skipped.size() && i < max_listed; ++i) {
    log << "skipped: " << out.input.skipped[i] << "\n";
  }
  if (out.input.skipped.size() > max_listed) {
    log << fmt::format("skipped: ... and {} more rows\n", out.input.skipped.size() - max_listed);
  }
  out.options = job.analysis;
  double diameter = job.ball_diameter_m;
  if (diameter <= 0) {
    diameter = out.input.layout == "tt3d" ? 0.04 : 0.22;
    log << fmt::format("ball diameter {:.3f} m ({}; --ball-diameter to change)\n", diameter,
                       out.input.layout == "tt3d" ? "table tennis, TT3D layout" : "football");
  }
  out.options.ball_radius_m = 0.5 * diameter;
  out.options.unmodelled_accel_mps2 =
      job.accel_slack_mps2 > 0 ? job.accel_slack_mps2 : (out.input.layout == "tt3d" ? 25.0 : 10.0);
  out.options.Check();
  FieldModel field;
  const bool has_field = !job.field.empty();
  if (has_field) field = LoadField(job.field);

  out.result = AnalyzeTrajectory(track, out.options);
  const TrajectoryResult& r = out.result;
  log << fmt::format("{}: {} samples, {:.2f} s; {}\n", job.in_path, track.size(),
                     track.empty() ? 0.0 : track.back().time_s - track.front().time_s, r.Summary());
  for (const auto& f : r.flights) {
    out.predictions.push_back(PredictFlightLanding(track, r, f, job.predict_fraction, out.options));
  }
  out.decisions = MakeDecisions(track, r, has_field ? &field : nullptr, out.options, job.decisions);

  // FLIGHTS.json: the contract's array, each flight with its prediction and calls.
  nlohmann::json flights = FlightsToJson(r);
  for (size_t i = 0; i < r.flights.size(); ++i) {
    const auto& p = out.predictions[i];
    nlohmann::json pj;
    pj["fraction"] = job.predict_fraction;
    pj["ok"] = p.ok;
    if (p.ok) {
      pj["samples_used"] = p.samples_used;
      pj["t_cut_s"] = p.t_cut_s;
      pj["landing"] = Vec3Json(p.landing_m);
      pj["t_landing_s"] = p.t_landing_s;
      pj["sigma_t_s"] = p.sigma_t_s;
      pj["ellipse95"] = {{"semi_major_m", p.semi_major_m},
                         {"semi_minor_m", p.semi_minor_m},
                         {"angle_deg", p.angle_rad * 180 / M_PI}};
      pj["error_to_fitted_landing_m"] =
          (p.landing_m.head<2>() - r.flights[i].landing_m.head<2>()).norm();
    }
    flights[i]["prediction"] = pj;
    nlohmann::json calls = nlohmann::json::array();
    const nlohmann::json dj = out.decisions.ToJson();
    for (const auto& c : dj["landings"]) {
      if (c["flight"] == static_cast<int>(i)) calls.push_back(c);
    }
    flights[i]["landing_calls"] = calls;
    nlohmann::json goals = nlohmann::json::array(), shots = nlohmann::json::array();
    for (const auto& g : dj["goal_crossings"]) {
      if (g["flight"] == static_cast<int>(i)) goals.push_back(g);
    }
    for (const auto& s : dj["made_shots"]) {
      if (s["flight"] == static_cast<int>(i)) shots.push_back(s);
    }
    flights[i]["goal_crossings"] = goals;
    flights[i]["made_shots"] = shots;
  }
  {
    std::ofstream f(job.out_path);
    FV_REQUIRE(f.good(), "cannot write '{}'", job.out_path);
    f << flights.dump(2) << "\n";
    FV_REQUIRE(f.good(), "cannot write '{}'", job.out_path);
  }
  if (!job.report_path.empty()) {
    nlohmann::json rep;
    rep["input"] = job.in_path;
    rep["layout"] = out.input.layout;
    rep["skipped_rows"] = out.input.skipped;
    rep["ball_radius_m"] = out.options.ball_radius_m;
    rep["gravity_mps2"] = out.options.gravity_mps2;
    rep["drag"] = DragModeName(out.options.drag);
    rep["noise_m"] = r.noise_m;
    rep["summary"] = r.Summary();
    rep["flights"] = flights;
    rep["decisions"] = out.decisions.ToJson();
    std::ofstream f(job.report_path);
    FV_REQUIRE(f.good(), "cannot write '{}'", job.report_path);
    f << rep.dump(2) << "\n";
  }
  if (!job.smoothed_path.empty()) {
    WriteBallTrack(job.smoothed_path, SmoothTrack(track, r, out.options, job.smoother));
  }
  if (!job.images_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(job.images_dir, ec);
    FV_REQUIRE(!ec, "cannot create folder '{}': {}", job.images_dir, ec.message());
    auto write = [&](const std::string& name, const cv::Mat& img) {
      const std::string p = (std::filesystem::path(job.images_dir) / name).string();
      WriteImage(p, img);
      out.images.push_back(p);
    };
    write("track_height.png", DrawTrackHeight(track, r, out.options));
    write("flights_top.png",
          DrawFlightsTop(track, r, has_field ? &field : nullptr, &out.decisions));
    for (size_t i = 0; i < r.flights.size(); ++i) {
      write(fmt::format("flight_{:02d}_side.png", i),
            DrawFlightSide(track, r, r.flights[i], out.options, &out.predictions[i]));
    }
  }
  // The flights and the timeline.
  log << fmt::format("{:>3} {:>14} {:>8} {:>8} {:>22} {:>22} {:>7} {:>7} {:>8} {:>8}\n", "#",
                     "events", "t0_s", "t1_s", "origin_m", "landing_m", "apex_m", "v0_mps",
                     "rmse_mm", "drag_mm");
  for (const auto& f : r.flights) {
    log << fmt::format(
        "{:>3} {:>14} {:8.3f} {:8.3f} {:>22} {:>22} {:7.2f} {:7.2f} {:8.1f} {:>8}\n", f.index,
        fmt::format("{}>{}", FlightEventName(f.start_event), FlightEventName(f.end_event)),
        f.t_start_s, f.t_end_s,
        fmt::format("({:.2f},{:.2f},{:.2f})", f.origin_m.x(), f.origin_m.y(), f.origin_m.z()),
        fmt::format("({:.2f},{:.2f},{:.2f}){}", f.landing_m.x(), f.landing_m.y(), f.landing_m.z(),
                    f.landing_extrapolated ? "*" : ""),
        f.apex_m.z(), f.speed_mps, f.no_drag.rmse_m * 1e3,
        f.with_drag.ok ? fmt::format("{:.1f}", f.with_drag.rmse_m * 1e3) : "-");
  }
  log << "timeline:\n";
  for (const auto& e : out.decisions.timeline) {
    log << fmt::format("  {:9.3f} s  {}\n", e.time_s, e.text);
  }
  log << fmt::format("wrote {} ({} flights){}\n", job.out_path, r.flights.size(),
                     out.images.empty()
                         ? ""
                         : fmt::format(", {} images in {}", out.images.size(), job.images_dir));
  return out;
}

}  // namespace fv
