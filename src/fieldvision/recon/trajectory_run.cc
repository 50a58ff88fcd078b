#include "fieldvision/recon/trajectory_run.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "fieldvision/recon/standard_balls.h"
#include "fieldvision/recon/trajectory_draw.h"
#include "fieldvision/recon/trajectory_eval.h"
#include "fieldvision/recon/trajectory_run_internal.h"
#include "fieldvision/util/csv.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/json.h"
#include "fieldvision/util/output_path.h"
#include "fieldvision/util/parallel.h"

namespace fv::recon {

void TrajectoryJob::Check() const {
  FV_REQUIRE(!in_path.empty(), "trajectory: --in is required");
  FV_REQUIRE(!out_path.empty(), "trajectory: --out is required");
  CheckInRange(ball_diameter_m, 0.0, 2.0, "ball_diameter_m");  // 0: the default
  CheckInRange(ball_mass_kg, 0.0, 100.0, "ball_mass_kg");
  CheckInRange(accel_slack_mps2, 0.0, 1000.0, "accel_slack_mps2");
  CheckInRange(predict_fraction, 0.05, 1.0, "predict_fraction");
  decisions.Check();
  smoother.Check();
}

std::string FlightTable(const TrajectoryResult& r) {
  std::string s = fmt::format(
      "{:>3} {:>21} {:>8} {:>8} {:>23} {:>23} {:>7} {:>7} {:>7} {:>8} {:>8} {:>8} {:>20}\n", "#",
      "events", "t0_s", "t1_s", "origin_m", "landing_m", "apex_m", "v0_mps", "model", "grav_mm",
      "drag_mm", "spin_mm", "spin rev/s (axis)");
  auto mm = [](const BallisticFit& b) {
    return b.ok ? fmt::format("{:.1f}", b.rmse_m * 1e3) : std::string("-");
  };
  for (const auto& f : r.flights) {
    std::string spin = "-";
    if (f.spin_used) {
      const Eigen::Vector3d w = f.model().spin_radps.normalized();
      spin = fmt::format("{:.0f} ({:.2f},{:.2f},{:.2f})", f.model().SpinRevPerS(), w.x(), w.y(),
                         w.z());
    }
    s += fmt::format(
        "{:>3} {:>21} {:8.3f} {:8.3f} {:>23} {:>23} {:7.2f} {:7.2f} {:>7} {:>8} {:>8} {:>8} "
        "{:>20}\n",
        f.index, fmt::format("{}>{}", FlightEventName(f.start_event), FlightEventName(f.end_event)),
        f.t_start_s, f.t_end_s,
        fmt::format("({:.2f},{:.2f},{:.2f}){}", f.origin_m.x(), f.origin_m.y(), f.origin_m.z(),
                    f.origin_extrapolated ? "*" : " "),
        fmt::format("({:.2f},{:.2f},{:.2f}){}", f.landing_m.x(), f.landing_m.y(), f.landing_m.z(),
                    f.landing_extrapolated ? "*" : " "),
        f.apex_m.z(), f.speed_mps, FlightModelName(f.model_kind()), mm(f.no_drag), mm(f.with_drag),
        mm(f.with_spin), spin);
  }
  s += "* extrapolated: the model's value beyond the samples seen (not measured); grav_mm, "
       "drag_mm, spin_mm: RMS residual of the fit with gravity alone, with drag, with drag and "
       "spin ('model' is the one kept)\n";
  return s;
}

namespace {

void CreateParentFolders(const TrajectoryJob& job) {
  for (const std::string* p : {&job.out_path, &job.report_path, &job.smoothed_path}) {
    const auto parent = std::filesystem::path(*p).parent_path();
    if (p->empty() || parent.empty()) continue;
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    FV_REQUIRE(!ec, "cannot create folder '{}' for '{}': {}", parent.string(), *p, ec.message());
  }
}

void LogSkipped(const BallTrackFile& input, std::ostream& log) {
  const size_t max_listed = 10;
  for (size_t i = 0; i < input.skipped.size() && i < max_listed; ++i) {
    log << "skipped: " << input.skipped[i] << "\n";
  }
  if (input.skipped.size() > max_listed) {
    log << fmt::format("skipped: ... and {} more rows\n", input.skipped.size() - max_listed);
  }
}

// Writes JSON through a temporary file beside `path`.
void WriteJson(const std::string& path, const nlohmann::json& j, const char* what) {
  util::AtomicWrite(
      path,
      [&](const std::string& tmp) {
        std::ofstream f(tmp);
        FV_REQUIRE(f.good(), "cannot write '{}'", path);
        f << j.dump(2) << "\n";
        f.close();
        FV_REQUIRE(!f.fail(), "cannot write '{}'", path);
      },
      what);
}

// The flights and the timeline.
void LogFlights(const TrajectoryJob& job, const TrajectoryJobResult& out, std::ostream& log) {
  const TrajectoryResult& r = out.result;
  log << FlightTable(r);
  log << "timeline:\n";
  for (const auto& e : out.decisions.timeline) {
    log << fmt::format("  {:9.3f} s  {}\n", e.time_s, e.text);
  }
  log << fmt::format("wrote {} ({} flights){}\n", job.out_path, r.flights.size(),
                     out.images.empty()
                         ? ""
                         : fmt::format(", {} images in {}", out.images.size(), job.images_dir));
}

}  // namespace

TrajectoryOptions TrajectoryOptionsFor(const TrajectoryJob& job, const std::string& layout,
                                       std::ostream& log) {
  TrajectoryOptions o = job.analysis;
  const bool tt3d = layout == "tt3d";
  double diameter = job.ball_diameter_m;
  if (diameter <= 0) {
    diameter = tt3d ? 0.04 : 0.22;
    log << fmt::format("ball diameter {:.3f} m ({}; --ball-diameter to change)\n", diameter,
                       tt3d ? "table tennis, TT3D layout" : "football");
  }
  o.ball_radius_m = 0.5 * diameter;
  o.ball_mass_kg = job.ball_mass_kg;
  if (o.ball_mass_kg > 0) {
    const std::string odd = BallMassWarning(diameter, o.ball_mass_kg);
    if (!odd.empty()) log << "warning: " << odd << "\n";
  } else {
    // The mass turns the fitted lift into rev/s: a 4 cm ball fitted as a football's 0.43 kg
    // gave a table-tennis track 2657 rev/s.
    const StandardBall& ball = NearestStandardBall(diameter);
    o.ball_mass_kg = ball.mass_kg;
    log << fmt::format(
        "ball mass {:.4g} kg (the standard ball nearest {:.3f} m across: {}, {:.3f} m; "
        "--ball-mass to change)\n",
        ball.mass_kg, diameter, ball.name, ball.diameter_m);
  }
  o.unmodelled_accel_mps2 = job.accel_slack_mps2 > 0 ? job.accel_slack_mps2 : (tt3d ? 25.0 : 10.0);
  o.Check();
  return o;
}

nlohmann::json FlightsJson(const TrajectoryJobResult& out, double predict_fraction) {
  const TrajectoryResult& r = out.result;
  // The calls sorted into their flights in one pass.
  nlohmann::json flights = FlightsToJson(r, &out.options);
  const nlohmann::json dj = out.decisions.ToJson();
  auto by_flight = [&](const char* key) {
    std::vector<nlohmann::json> per(r.flights.size(), nlohmann::json::array());
    for (const auto& c : dj[key]) {
      const int f = c["flight"].get<int>();
      if (f >= 0 && f < static_cast<int>(per.size())) per[f].push_back(c);
    }
    return per;
  };
  const auto landing_calls = by_flight("landings");
  const auto goal_crossings = by_flight("goal_crossings");
  const auto made_shots = by_flight("made_shots");
  for (size_t i = 0; i < r.flights.size(); ++i) {
    const auto& p = out.predictions[i];
    nlohmann::json pj;
    pj["fraction"] = predict_fraction;
    pj["ok"] = p.ok;
    if (p.ok) {
      pj["samples_used"] = p.samples_used;
      pj["t_cut_s"] = p.t_cut_s;
      pj["landing"] = util::JsonFromVector(p.landing_m, 4);
      pj["t_landing_s"] = p.t_landing_s;
      pj["sigma_t_s"] = p.sigma_t_s;
      pj["ellipse95"] = {{"semi_major_m", p.semi_major_m},
                         {"semi_minor_m", p.semi_minor_m},
                         {"angle_deg", p.angle_rad * 180 / M_PI}};
      pj["error_to_fitted_landing_m"] =
          (p.landing_m.head<2>() - r.flights[i].landing_m.head<2>()).norm();
    }
    flights[i]["prediction"] = pj;
    flights[i]["landing_calls"] = landing_calls[i];
    flights[i]["goal_crossings"] = goal_crossings[i];
    flights[i]["made_shots"] = made_shots[i];
  }
  return flights;
}

void WriteTrajectoryOutputs(const TrajectoryJob& job, const nlohmann::json& flights,
                            const field::FieldModel* field, TrajectoryJobResult& out) {
  const auto& track = out.input.samples;
  const TrajectoryResult& r = out.result;
  // Everything is computed and the pictures' folder made before the first output is replaced;
  // each output is written to a temporary file beside it and renamed (io/output_path.h).
  if (!job.images_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(job.images_dir, ec);
    FV_REQUIRE(!ec && std::filesystem::is_directory(job.images_dir),
               "cannot create the folder '{}' for --images{}", job.images_dir,
               ec ? ": " + ec.message() : std::string());
  }
  WriteJson(job.out_path, flights, "--out");
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
    WriteJson(job.report_path, rep, "--report");
  }
  if (!job.smoothed_path.empty()) {
    const std::vector<BallSample> smoothed = SmoothTrack(track, r, out.options, job.smoother);
    util::AtomicWrite(
        job.smoothed_path, [&](const std::string& tmp) { WriteBallTrack(tmp, smoothed); },
        "--smoothed");
  }
  if (job.images_dir.empty()) return;
  // Drawn one at a time (a long track has thousands of flights).
  auto write = [&](const std::string& name, const cv::Mat& img) {
    const std::string path = (std::filesystem::path(job.images_dir) / name).string();
    io::WriteImage(path, img);
    out.images.push_back(path);
  };
  write("track_height.png", DrawTrackHeight(track, r, out.options));
  write("flights_top.png", DrawFlightsTop(track, r, field, &out.decisions));
  for (size_t i = 0; i < r.flights.size(); ++i) {
    write(fmt::format("flight_{:02d}_side.png", i),
          DrawFlightSide(track, r, r.flights[i], out.options, &out.predictions[i]));
  }
}

TrajectoryJobResult RunTrajectory(const TrajectoryJob& job, std::ostream& log) {
  job.Check();
  CreateParentFolders(job);
  TrajectoryJobResult out;
  out.input = ReadBallTrack(job.in_path);
  const auto& track = out.input.samples;
  LogSkipped(out.input, log);
  out.options = TrajectoryOptionsFor(job, out.input.layout, log);
  field::FieldModel field;
  const bool has_field = !job.field.empty();
  if (has_field) field = field::LoadField(job.field);
  if (has_field && out.input.layout == "tt3d") {
    // TT3D files have the table's length along y: the field is turned to match.
    field = RotateFieldQuarter(field);
    log << "field turned a quarter (TT3D layout: the table's length along y)\n";
  }
  out.result = AnalyzeTrajectory(track, out.options);
  const TrajectoryResult& r = out.result;
  log << fmt::format("{}: {} samples, {:.2f} s; {}\n", job.in_path, track.size(),
                     track.empty() ? 0.0 : track.back().time_s - track.front().time_s, r.Summary());
  out.predictions.resize(r.flights.size());
  util::ParallelFor(r.flights.size(), [&](size_t i) {
    out.predictions[i] =
        PredictFlightLanding(track, r, r.flights[i], job.predict_fraction, out.options);
  });
  out.decisions = MakeDecisions(track, r, has_field ? &field : nullptr, out.options, job.decisions);
  const nlohmann::json flights = FlightsJson(out, job.predict_fraction);
  WriteTrajectoryOutputs(job, flights, has_field ? &field : nullptr, out);
  LogFlights(job, out, log);
  return out;
}

namespace {

// fnmatch-like: '*' any run, '?' one character.
bool Match(const char* pat, const char* str) {
  if (*pat == '\0') return *str == '\0';
  if (*pat == '*') return Match(pat + 1, str) || (*str != '\0' && Match(pat, str + 1));
  if (*str == '\0') return false;
  return (*pat == '?' || *pat == *str) && Match(pat + 1, str + 1);
}

}  // namespace

std::vector<std::string> ExpandTrackInputs(const std::string& in) {
  namespace fs = std::filesystem;
  std::vector<std::string> out;
  const bool glob = in.find_first_of("*?") != std::string::npos;
  if (!glob && !fs::is_directory(in)) return out;
  const fs::path dir = glob ? fs::path(in).parent_path() : fs::path(in);
  const std::string pattern = glob ? fs::path(in).filename().string() : "*.csv";
  FV_REQUIRE(fs::is_directory(dir.empty() ? fs::path(".") : dir),
             "trajectory: no folder '{}' for '{}'", dir.string(), in);
  for (const auto& e : fs::directory_iterator(dir.empty() ? fs::path(".") : dir)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().filename().string();
    if (Match(pattern.c_str(), name.c_str())) out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  FV_REQUIRE(!out.empty(), "trajectory: '{}' matches no track file", in);
  return out;
}

TrajectoryBatchResult RunTrajectoryBatch(const TrajectoryJob& job,
                                         const std::vector<std::string>& files, std::ostream& log) {
  namespace fs = std::filesystem;
  FV_REQUIRE(!job.out_path.empty(), "trajectory: --out is required (a folder in batch mode)");
  std::error_code ec;
  fs::create_directories(job.out_path, ec);
  FV_REQUIRE(!ec && fs::is_directory(job.out_path),
             "trajectory: cannot create the output folder '{}' (batch mode writes one JSON per "
             "track there)",
             job.out_path);
  TrajectoryBatchResult res;
  res.files = files;
  res.summary_csv = (fs::path(job.out_path) / "summary.csv").string();
  util::AtomicOutput summary(res.summary_csv, "summary.csv");
  std::vector<BounceTrackScore> scores;
  {
    util::CsvWriter csv(summary.temp_path(), {"file",           "flight",
                                              "start_event",    "end_event",
                                              "t_start_s",      "t_end_s",
                                              "origin_x_m",     "origin_y_m",
                                              "origin_z_m",     "origin_extrapolated",
                                              "landing_x_m",    "landing_y_m",
                                              "landing_z_m",    "landing_extrapolated",
                                              "apex_z_m",       "speed_mps",
                                              "model",          "rmse_m",
                                              "rmse_gravity_m", "rmse_drag_m",
                                              "rmse_spin_m",    "rmse_free_accel_m",
                                              "spin_revps",     "spin_axis_x",
                                              "spin_axis_y",    "spin_axis_z"},
                        5);
    for (const auto& file : files) {
      const std::string stem = fs::path(file).stem().string();
      TrajectoryJob j = job;
      j.in_path = file;
      j.out_path = (fs::path(job.out_path) / (stem + ".json")).string();
      if (!job.images_dir.empty()) j.images_dir = (fs::path(job.images_dir) / stem).string();
      if (!job.report_path.empty()) j.report_path.clear();
      if (!job.smoothed_path.empty()) {
        j.smoothed_path = (fs::path(job.out_path) / (stem + "_smoothed.csv")).string();
      }
      std::ostringstream quiet;
      TrajectoryJobResult r;
      try {
        r = RunTrajectory(j, quiet);
      } catch (const Error& e) {
        res.failed.push_back(fmt::format("{}: {}", file, e.what()));
        log << "failed: " << res.failed.back() << "\n";
        continue;
      }
      auto rm = [](const BallisticFit& b) { return b.ok ? b.rmse_m : -1.0; };
      for (const auto& f : r.result.flights) {
        const Eigen::Vector3d w = f.spin_used ? Eigen::Vector3d(f.model().spin_radps.normalized())
                                              : Eigen::Vector3d::Zero();
        csv << fs::path(file).filename().string() << f.index << FlightEventName(f.start_event)
            << FlightEventName(f.end_event) << f.t_start_s << f.t_end_s << f.origin_m.x()
            << f.origin_m.y() << f.origin_m.z() << (f.origin_extrapolated ? 1 : 0)
            << f.landing_m.x() << f.landing_m.y() << f.landing_m.z()
            << (f.landing_extrapolated ? 1 : 0) << f.apex_m.z() << f.speed_mps
            << FlightModelName(f.model_kind()) << f.rmse_m << rm(f.no_drag) << rm(f.with_drag)
            << rm(f.with_spin) << (f.free_accel.ok ? f.free_accel.rmse_m : -1.0)
            << (f.spin_used ? f.model().SpinRevPerS() : 0.0) << w.x() << w.y() << w.z();
        csv.EndRow();
      }
      log << fmt::format("{}: {}\n", file, r.result.Summary());
      bool bounce = false;
      for (const auto& b : r.result.breaks) bounce |= b.kind == FlightEvent::kBounce;
      if (bounce) scores.push_back(ScoreBounceTrack(file, r.input.samples, r.options));
    }
    // Nothing fitted: no summary of nothing (an earlier one is kept).
    FV_REQUIRE(res.failed.size() < files.size(),
               "trajectory: none of the {} tracks could be read or fitted (the first: {})",
               files.size(), res.failed.empty() ? "" : res.failed.front());
    summary.CloseAndCommit(csv);
  }
  if (!scores.empty()) log << Summarize(scores).Table();
  log << fmt::format("wrote {} ({} tracks, {} failed; -1: not fitted)\n", res.summary_csv,
                     files.size() - res.failed.size(), res.failed.size());
  return res;
}

}  // namespace fv::recon
