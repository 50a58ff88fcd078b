#include "fieldvision/recon/ball_csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/stats.h"

namespace fv::recon {

const std::vector<std::string>& BallCsvColumns() {
  static const std::vector<std::string> kColumns = {"frame", "time_s", "x_m",   "y_m",
                                                    "z_m",   "n_cams", "err_px"};
  return kColumns;
}

namespace {

// A cell read as CsvTable::GetDouble/GetInt read it (cells are trimmed; from_chars and strtod
// round alike), without formatting the error's context for every cell (a 2,000,000-row track
// spent seconds on it): whatever the quick read does not take goes through GetDouble/GetInt,
// which name the file, line and column.
double Number(const util::CsvTable& t, size_t r, const std::string& column) {
  const std::string& cell = t.Get(r, column);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec == std::errc() && end == cell.data() + cell.size() && !cell.empty()) return v;
  return t.GetDouble(r, column);
}

long long Integer(const util::CsvTable& t, size_t r, const std::string& column) {
  const std::string& cell = t.Get(r, column);
  long long v = 0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec == std::errc() && end == cell.data() + cell.size() && !cell.empty()) return v;
  return t.GetInt(r, column);
}

}  // namespace

BallSample ReadBallCsvRow(const util::CsvTable& t, size_t r) {
  BallSample s;
  if (t.Has("time_s")) s.time_s = Number(t, r, "time_s");
  s.ball_in_world = {Number(t, r, "x_m"), Number(t, r, "y_m"), Number(t, r, "z_m")};
  if (t.Has("frame")) s.frame = Integer(t, r, "frame");
  if (t.Has("n_cams")) s.n_cams = static_cast<int>(Integer(t, r, "n_cams"));
  if (t.Has("err_px")) s.err_px = Number(t, r, "err_px");
  return s;
}

namespace {
constexpr double kMaxPositionM = 1e4;
}  // namespace

void CheckBallTrackRanges(const util::CsvTable& table) {
  constexpr double kMaxFrame = 1e8, kMaxTimeS = 1e11;
  for (size_t r = 0; r < table.rows(); ++r) {
    const BallSample s = ReadBallCsvRow(table, r);
    if (table.Has("frame")) {
      FV_REQUIRE(s.frame >= 0 && s.frame <= kMaxFrame, "{}: frame {} is not in [0, {:.0f}]",
                 table.Where(r), s.frame, kMaxFrame);
    }
    for (int k = 0; k < 3; ++k) {
      FV_REQUIRE(std::abs(s.ball_in_world[k]) <= kMaxPositionM,
                 "{}: {} = {} is not a finite position within +-{:.0f} m", table.Where(r),
                 "xyz"[k] + std::string("_m"), s.ball_in_world[k], kMaxPositionM);
    }
    if (table.Has("time_s") && !table.Get(r, "time_s").empty()) {
      FV_REQUIRE(std::abs(s.time_s) <= kMaxTimeS, "{}: time_s = {} is not a finite time",
                 table.Where(r), s.time_s);
    }
  }
}

namespace {

BallSample ReadTt3dRow(const util::CsvTable& t, size_t r) {
  BallSample s;
  s.time_s = Number(t, r, "Timestamp");
  s.ball_in_world = {Number(t, r, "X"), Number(t, r, "Y"), Number(t, r, "Z")};
  return s;
}

}  // namespace

BallTrackFile ParseBallTrack(const util::CsvTable& t) {
  BallTrackFile out;
  if (t.Has("time_s") || t.Has("x_m") || t.Has("frame")) {
    t.Require({"time_s", "x_m", "y_m", "z_m"});
    out.layout = "ball";
  } else if (t.Has("Timestamp")) {
    t.Require({"Timestamp", "X", "Y", "Z"});
    out.layout = "tt3d";
  } else {
    Throw(
        "ball track '{}': unknown columns (expected frame,time_s,x_m,y_m,z_m,n_cams,err_px "
        "or Timestamp,X,Y,Z)",
        t.name());
  }
  int out_of_order = 0;
  for (size_t r = 0; r < t.rows(); ++r) {
    BallSample s;
    try {
      s = out.layout == "ball" ? ReadBallCsvRow(t, r) : ReadTt3dRow(t, r);
    } catch (const Error& e) {
      out.skipped.push_back(fmt::format("{}; row skipped", e.what()));
      continue;
    }
    if (!std::isfinite(s.time_s) || !s.ball_in_world.allFinite()) {
      out.skipped.push_back(
          fmt::format("{}: NaN or infinite time or position; row skipped", t.Where(r)));
      continue;
    }
    if (s.ball_in_world.cwiseAbs().maxCoeff() > kMaxPositionM) {
      out.skipped.push_back(
          fmt::format("{}: position more than {:.0f} m from the origin; row "
                      "skipped",
                      t.Where(r), kMaxPositionM));
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
  CheckBallTrackUnits(out.samples, t.name());
  return out;
}

void CheckBallTrackUnits(const std::vector<BallSample>& samples, const std::string& name) {
  // Rows 1 s apart or more, or a ball that moves faster than any ball is hit (the fastest
  // shuttlecock smash is about 140 m/s) over 0.2 s, half the time: not seconds and metres. (Over
  // 0.2 s, not from one row to the next: 30 cm of noise at 240 Hz is 150 m/s between rows.)
  constexpr double kMaxMedianStepS = 1.0, kMaxMedianSpeedMps = 150.0, kBaselineS = 0.2;
  if (samples.size() < 3) return;
  std::vector<double> steps_s, speeds_mps;
  size_t j = 0;
  for (size_t i = 0; i + 1 < samples.size(); ++i) {
    steps_s.push_back(samples[i + 1].time_s - samples[i].time_s);
    j = std::max(j, i + 1);
    while (j + 1 < samples.size() && samples[j].time_s - samples[i].time_s < kBaselineS) ++j;
    speeds_mps.push_back((samples[j].ball_in_world - samples[i].ball_in_world).norm() /
                         (samples[j].time_s - samples[i].time_s));
  }
  const double step_s = util::Median(steps_s), speed_mps = util::Median(speeds_mps);
  FV_REQUIRE(step_s < kMaxMedianStepS,
             "ball track '{}': rows are {:.4g} s apart (the median): are its times in seconds "
             "(not milliseconds or frames)?",
             name, step_s);
  FV_REQUIRE(speed_mps < kMaxMedianSpeedMps,
             "ball track '{}': the ball moves {:.4g} m/s (the median over 0.2 s), faster than any "
             "ball: are its positions in metres (not millimetres)?",
             name, speed_mps);
}

BallTrackFile ReadBallTrack(const std::string& path) {
  return ParseBallTrack(util::CsvTable::Read(path));
}

void WriteBallTrack(const std::string& path, const std::vector<BallSample>& samples) {
  util::CsvWriter w(path, BallCsvColumns());
  for (const auto& s : samples) {
    w << s.frame << s.time_s << s.ball_in_world.x() << s.ball_in_world.y() << s.ball_in_world.z()
      << s.n_cams << s.err_px;
    w.EndRow();
  }
  w.Close();
}

}  // namespace fv::recon
