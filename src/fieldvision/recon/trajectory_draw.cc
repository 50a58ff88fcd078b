#include "fieldvision/recon/trajectory_draw.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "fieldvision/field/field_draw.h"
#include "fieldvision/util/error.h"

namespace fv::recon {
namespace {

const cv::Scalar kWhite(255, 255, 255), kBlack(0, 0, 0), kGrey(150, 150, 150);
const cv::Scalar kGreen(40, 170, 40), kRed(40, 40, 230), kBlue(200, 90, 20);
const cv::Scalar kOrange(0, 140, 255), kPurple(180, 40, 160), kDark(60, 60, 60);

// A linear map from a data box to a pixel box (y up).
struct Axes {
  double x0, x1, y0, y1;
  cv::Rect box;
  cv::Point2d P(double x, double y) const {
    return {box.x + (x - x0) / (x1 - x0) * box.width,
            box.y + box.height - (y - y0) / (y1 - y0) * box.height};
  }
};

void DrawGrid(cv::Mat& img, const Axes& a, const std::string& xlabel, const std::string& ylabel) {
  const double sx = field::NiceStep(a.x1 - a.x0), sy = field::NiceStep(a.y1 - a.y0);
  for (double x = std::ceil(a.x0 / sx) * sx; x <= a.x1; x += sx) {
    cv::line(img, a.P(x, a.y0), a.P(x, a.y1), cv::Scalar(225, 225, 225), 1);
    cv::putText(img, fmt::format("{:g}", field::TickValue(x, sx)),
                a.P(x, a.y0) + cv::Point2d(-10, 18), cv::FONT_HERSHEY_SIMPLEX, 0.45, kDark, 1,
                cv::LINE_AA);
  }
  for (double y = std::ceil(a.y0 / sy) * sy; y <= a.y1; y += sy) {
    cv::line(img, a.P(a.x0, y), a.P(a.x1, y), cv::Scalar(225, 225, 225), 1);
    cv::putText(img, fmt::format("{:g}", field::TickValue(y, sy)),
                a.P(a.x0, y) + cv::Point2d(-48, 5), cv::FONT_HERSHEY_SIMPLEX, 0.45, kDark, 1,
                cv::LINE_AA);
  }
  cv::rectangle(img, a.box, kDark, 1);
  cv::putText(img, xlabel, cv::Point(a.box.x + a.box.width / 2 - 60, a.box.br().y + 38),
              cv::FONT_HERSHEY_SIMPLEX, 0.5, kBlack, 1, cv::LINE_AA);
  // Above the top tick label (drawn up to 5 px above the box's top).
  cv::putText(img, ylabel, cv::Point(5, std::max(14, a.box.y - 18)), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              kBlack, 1, cv::LINE_AA);
}

// A curve clipped to the plot's box (a model run past the data stays out of the tick labels).
void CurveInBox(cv::Mat& img, const cv::Rect& box, std::vector<cv::Point> pts, const cv::Scalar& c,
                int thickness) {
  for (cv::Point& p : pts) p -= box.tl();
  cv::Mat inside = img(box & cv::Rect({0, 0}, img.size()));
  cv::polylines(inside, pts, false, c, thickness, cv::LINE_AA);
}

void Text(cv::Mat& img, const std::string& s, cv::Point p, const cv::Scalar& c,
          double scale = 0.5) {
  cv::putText(img, s, p, cv::FONT_HERSHEY_SIMPLEX, scale, c, 1, cv::LINE_AA);
}

void Cross(cv::Mat& img, cv::Point2d p, const cv::Scalar& c, int r = 5) {
  cv::line(img, p + cv::Point2d(-r, -r), p + cv::Point2d(r, r), c, 2, cv::LINE_AA);
  cv::line(img, p + cv::Point2d(-r, r), p + cv::Point2d(r, -r), c, 2, cv::LINE_AA);
}

cv::Scalar FlightColour(int i) {
  // No green or red: those mark the samples, in / out calls and outliers.
  static const cv::Scalar kColours[] = {kBlue, kOrange, kPurple, cv::Scalar(40, 90, 150),
                                        cv::Scalar(160, 120, 0)};
  return kColours[i % 5];
}

}  // namespace

cv::Mat DrawFlightSide(const std::vector<BallSample>& track, const TrajectoryResult& result,
                       const Flight& f, const TrajectoryOptions& o, const LandingPrediction* pred,
                       cv::Size size) {
  cv::Mat img(size, CV_8UC3, kWhite);
  Eigen::Vector2d dir = (f.landing_m - f.origin_m).head<2>();
  if (dir.norm() < 1e-6) dir = Eigen::Vector2d::UnitX();
  dir.normalize();
  const Eigen::Vector2d xy0 = f.origin_m.head<2>();
  auto s_of = [&](const Eigen::Vector3d& p) { return (p.head<2>() - xy0).dot(dir); };
  const double t0 = std::min(f.t_start_s, f.t_first_seen_s);
  const double t1 = std::max(f.t_landing_s, f.t_last_seen_s);
  // Extents.
  double smin = 0, smax = 0, zmin = o.ground_z_m, zmax = f.apex_m.z();
  auto grow = [&](const Eigen::Vector3d& p) {
    smin = std::min(smin, s_of(p));
    smax = std::max(smax, s_of(p));
    zmin = std::min(zmin, p.z());
    zmax = std::max(zmax, p.z());
  };
  for (int i : f.samples) grow(track[i].ball_in_world);
  grow(f.landing_m);
  if (pred && pred->ok) grow(pred->landing_m);
  const double ms = 0.05 * (smax - smin) + 0.05, mz = 0.1 * (zmax - zmin) + 0.05;
  Axes a{smin - ms, smax + ms, zmin - mz, zmax + mz,
         cv::Rect(70, 100, size.width - 100, size.height - 190)};
  DrawGrid(img, a, "horizontal distance along the flight from the origin (m)", "height z (m)");
  cv::line(img, a.P(a.x0, o.ground_z_m), a.P(a.x1, o.ground_z_m), kDark, 2);
  auto curve = [&](const BallisticModel& m, double ta, double tb, const cv::Scalar& c, int th) {
    if (tb <= ta) return;
    std::vector<cv::Point> pts;
    const int steps = 200;
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector3d p = m.PositionAt(ta + (tb - ta) * k / steps);
      pts.push_back(a.P(s_of(p), p.z()));
    }
    CurveInBox(img, a.box, std::move(pts), c, th);
  };
  // Other model thin, chosen model thick, seed quadratic orange.
  if (f.model_kind() != FlightModel::kGravity && f.no_drag.ok) {
    curve(f.no_drag.model, t0, t1, kGrey, 1);
  }
  if (f.model_kind() != FlightModel::kDrag && f.with_drag.ok) {
    curve(f.with_drag.model, t0, t1, kGrey, 1);
  }
  if (f.seed.ok) {
    std::vector<cv::Point> pts;
    for (int k = 0; k <= 100; ++k) {
      const double u = k / 100.0;
      const Eigen::Vector3d po = f.seed.origin_m, pl = f.seed.landing_m;
      const double so = s_of(po), sl = s_of(pl);
      const double s = so + u * (sl - so);
      // The seed's parabola through origin, apex and landing (in s).
      const double sa = s_of(f.seed.apex_m);
      const double h = f.seed.apex_m.z() - po.z();
      const double w = std::max(std::abs(sa - so), 1e-6);
      const double z = f.seed.apex_m.z() - h * (s - sa) * (s - sa) / (w * w);
      pts.push_back(a.P(s, z));
    }
    CurveInBox(img, a.box, std::move(pts), kOrange, 1);
  }
  // The chosen model: thick over the seen samples, thin where it is extrapolated.
  curve(f.model(), t0, f.t_first_seen_s, kBlue, 1);
  curve(f.model(), f.t_first_seen_s, f.t_last_seen_s, kBlue, 2);
  curve(f.model(), f.t_last_seen_s, t1, kBlue, 1);
  for (int i : f.samples) {
    const auto& p = track[i].ball_in_world;
    if (result.outlier[i]) {
      Cross(img, a.P(s_of(p), p.z()), kRed);
    } else {
      cv::circle(img, a.P(s_of(p), p.z()), 3, kGreen, cv::FILLED, cv::LINE_AA);
    }
  }
  cv::circle(img, a.P(s_of(f.origin_m), f.origin_m.z()), 7, kBlack,
             f.origin_extrapolated ? 1 : cv::FILLED, cv::LINE_AA);
  cv::circle(img, a.P(s_of(f.landing_m), f.landing_m.z()), 7, kBlack,
             f.landing_extrapolated ? 1 : cv::FILLED, cv::LINE_AA);
  cv::drawMarker(img, a.P(s_of(f.apex_m), f.apex_m.z()), kBlack, cv::MARKER_TRIANGLE_UP, 12, 2);
  if (pred && pred->ok) {
    const cv::Point2d pl = a.P(s_of(pred->landing_m), pred->landing_m.z());
    cv::drawMarker(img, pl, kPurple, cv::MARKER_DIAMOND, 14, 2);
    const double e = pred->semi_major_m;
    cv::line(img, a.P(s_of(pred->landing_m) - e, pred->landing_m.z()),
             a.P(s_of(pred->landing_m) + e, pred->landing_m.z()), kPurple, 2);
  }
  Text(img,
       fmt::format(
           "flight {}: {} -> {}, t {:.3f}..{:.3f} s ({:.2f} s), v0 {:.2f} m/s, apex {:.2f} m",
           f.index, FlightEventName(f.start_event), FlightEventName(f.end_event), f.t_start_s,
           f.t_end_s, f.FlightTime(), f.speed_mps, f.apex_m.z()),
       {10, 22}, kBlack, 0.55);
  std::string fits = fmt::format("rmse: gravity {:.1f} mm", f.no_drag.rmse_m * 1e3);
  if (f.with_drag.ok) {
    fits += fmt::format(", drag {:.1f} mm (k {:.3f}/m)", f.with_drag.rmse_m * 1e3,
                        f.with_drag.model.drag_per_m);
  }
  if (f.with_spin.ok) fits += fmt::format(", spin {:.1f} mm", f.with_spin.rmse_m * 1e3);
  if (f.free_accel.ok) fits += fmt::format(", free accel. {:.1f} mm", f.free_accel.rmse_m * 1e3);
  if (f.seed.ok) fits += fmt::format(", seed quadratic {:.1f} mm", f.seed.rmse_m * 1e3);
  fits += fmt::format("  [blue: {} model]", FlightModelName(f.model_kind()));
  if (f.spin_used) {
    const Eigen::Vector3d w = f.model().spin_radps.normalized();
    Text(img,
         fmt::format("spin {:.0f} rev/s about ({:.2f}, {:.2f}, {:.2f}) (Magnus, lift slope as "
                     "configured), drag k {:.3f}/m",
                     f.model().SpinRevPerS(), w.x(), w.y(), w.z(), f.model().drag_per_m),
         {10, 66}, kDark);
  }
  Text(img, fits, {10, 44}, kDark);
  Text(img,
       "green: samples, red x: outliers, blue: fit (thin: extrapolated beyond the samples), grey: "
       "other models, orange: seed quadratic,",
       {10, size.height - 26}, kDark, 0.42);
  Text(img,
       "purple: landing predicted from the first half (bar: 95 % semi-axis); origin/landing "
       "circles hollow: extrapolated, filled: seen",
       {10, size.height - 8}, kDark, 0.42);
  return img;
}

cv::Mat DrawTrackHeight(const std::vector<BallSample>& track, const TrajectoryResult& result,
                        const TrajectoryOptions& o, cv::Size size) {
  cv::Mat img(size, CV_8UC3, kWhite);
  if (track.empty()) return img;
  double zmax = o.ground_z_m + 2 * o.ball_radius_m, zmin = o.ground_z_m;
  for (const auto& s : track) {
    zmax = std::max(zmax, s.ball_in_world.z());
    zmin = std::min(zmin, s.ball_in_world.z());
  }
  const double t0 = track.front().time_s, t1 = track.back().time_s;
  const double mt = 0.02 * (t1 - t0) + 1e-3, mz = 0.08 * (zmax - zmin) + 0.02;
  Axes a{t0 - mt, t1 + mt, zmin - mz, zmax + mz,
         cv::Rect(70, 64, size.width - 100, size.height - 124)};  // the title, then the y label
  DrawGrid(img, a, "time (s)", "height z (m)");
  cv::line(img, a.P(a.x0, o.ground_z_m), a.P(a.x1, o.ground_z_m), kDark, 2);
  for (const auto& f : result.flights) {
    std::vector<cv::Point> pts;
    for (int k = 0; k <= 150; ++k) {
      const double t = f.t_start_s + (f.t_end_s - f.t_start_s) * k / 150.0;
      pts.push_back(a.P(t, f.model().PositionAt(t).z()));
    }
    CurveInBox(img, a.box, std::move(pts), FlightColour(f.index), 2);
    Text(img, std::to_string(f.index), a.P(f.t_apex_s, f.apex_m.z()) + cv::Point2d(-5, -10),
         FlightColour(f.index));
  }
  for (const auto& b : result.breaks) {
    cv::line(img, a.P(b.time_s, a.y0), a.P(b.time_s, a.y1),
             b.kind == FlightEvent::kBounce ? kGrey : kRed, 1);
    Text(img, b.kind == FlightEvent::kBounce ? "B" : "H", a.P(b.time_s, a.y1) + cv::Point2d(-4, -4),
         b.kind == FlightEvent::kBounce ? kDark : kRed);
  }
  for (size_t i = 0; i < track.size(); ++i) {
    const cv::Point2d p = a.P(track[i].time_s, track[i].ball_in_world.z());
    if (result.outlier[i]) {
      Cross(img, p, kRed, 4);
    } else {
      cv::circle(img, p, 2, result.on_ground[i] ? kGrey : kGreen, cv::FILLED, cv::LINE_AA);
    }
  }
  Text(img, result.Summary(), {10, 22}, kBlack, 0.5);
  Text(img,
       "green: airborne samples, grey: on the ground, red x: outliers, coloured: fitted flights, "
       "B: bounce, H: hit",
       {10, size.height - 8}, kDark, 0.42);
  return img;
}

field::FieldModel RotateFieldQuarter(const field::FieldModel& f) {
  field::FieldModel r = f;
  auto rot = [](const Eigen::Vector2d& p) { return Eigen::Vector2d(-p.y(), p.x()); };
  std::swap(r.length_m, r.width_m);
  for (auto& sgm : r.segments) sgm.a = rot(sgm.a), sgm.b = rot(sgm.b);
  for (auto& a : r.arcs) {
    a.centre = rot(a.centre);
    a.start_rad += M_PI / 2;
    a.end_rad += M_PI / 2;
  }
  for (auto& k : r.keypoints) {
    const Eigen::Vector2d q = rot(k.position_m.head<2>());
    k.position_m.x() = q.x();
    k.position_m.y() = q.y();
  }
  r.goals.clear();  // goals are defined on lines x = const
  for (auto& h : r.hoops) {
    const Eigen::Vector2d q = rot(h.centre_m.head<2>());
    h.centre_m.x() = q.x();
    h.centre_m.y() = q.y();
  }
  return r;
}

cv::Mat DrawFlightsTop(const std::vector<BallSample>& track, const TrajectoryResult& result,
                       const field::FieldModel* field, const Decisions* decisions, int width_px) {
  field::TopView view;
  cv::Mat img;
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  auto grow = [&](const Eigen::Vector3d& p) {
    x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x());
    y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
  };
  for (const auto& s : track) grow(s.ball_in_world);
  for (const auto& f : result.flights) grow(f.landing_m), grow(f.origin_m);
  if (track.empty()) x0 = y0 = -1, x1 = y1 = 1;
  if (field && field->length_m > 0) {
    // The field plus whatever of the track lies beyond its surround.
    const double ex =
        std::max({0.0, x1 - field->HalfLengthWithSurround(), -x0 - field->HalfLengthWithSurround(),
                  y1 - field->HalfWidthWithSurround(), -y0 - field->HalfWidthWithSurround()});
    view = field::TopView::ForField(*field, width_px, std::min(ex + 0.2, 50.0));
    field::FieldDrawOptions fo;
    fo.keypoints = false;
    img = field::DrawField(*field, view, fo);
    // A table-tennis net across the middle (x = 0).
    for (const auto& k : field->keypoints) {
      if (k.name == "net_post_top") {
        const cv::Point2d a = view.ToPixel(k.position_m.head<2>());
        const cv::Point2d b = view.ToPixel(-k.position_m.head<2>());
        cv::line(img, a, b, cv::Scalar(30, 30, 30), 3, cv::LINE_AA);
      }
    }
  } else {
    const double m = 0.1 * std::max(x1 - x0, y1 - y0) + 0.2;
    x0 -= m, x1 += m, y0 -= m, y1 += m;
    view.px_per_m = width_px / (x1 - x0);
    view.x_min_m = x0;
    view.y_max_m = y1;
    view.size = cv::Size(width_px, std::max(50, static_cast<int>((y1 - y0) * view.px_per_m)));
    img = cv::Mat(view.size, CV_8UC3, cv::Scalar(70, 70, 70));
    const double step = field::NiceStep(x1 - x0);
    for (double x = std::ceil(x0 / step) * step; x <= x1; x += step) {
      cv::line(img, view.ToPixel({x, y0}), view.ToPixel({x, y1}), cv::Scalar(95, 95, 95), 1);
    }
    for (double y = std::ceil(y0 / step) * step; y <= y1; y += step) {
      cv::line(img, view.ToPixel({x0, y}), view.ToPixel({x1, y}), cv::Scalar(95, 95, 95), 1);
    }
  }
  for (size_t i = 0; i < track.size(); ++i) {
    const cv::Point2d p = view.ToPixel(track[i].ball_in_world.head<2>());
    if (result.outlier[i]) {
      Cross(img, p, kRed, 3);
    } else {
      cv::circle(img, p, 2, cv::Scalar(220, 220, 220), cv::FILLED, cv::LINE_AA);
    }
  }
  for (const auto& f : result.flights) {
    // Seen part solid, extrapolated parts thin.
    auto arc = [&](double ta, double tb, int thickness) {
      if (tb <= ta) return;
      std::vector<cv::Point> pts;
      for (int k = 0; k <= 60; ++k) {
        const double t = ta + (tb - ta) * k / 60.0;
        pts.push_back(view.ToPixel(f.model().PositionAt(t).head<2>()));
      }
      cv::polylines(img, pts, false, FlightColour(f.index), thickness, cv::LINE_AA);
    };
    const double tb = std::max(f.t_end_s, f.t_landing_s);
    arc(f.t_start_s, f.t_first_seen_s, 1);
    arc(std::max(f.t_start_s, f.t_first_seen_s), std::min(tb, f.t_last_seen_s), 2);
    arc(f.t_last_seen_s, tb, 1);
    // Origin and landing: filled when seen, hollow when extrapolated.
    cv::circle(img, view.ToPixel(f.origin_m.head<2>()), 5, kBlack,
               f.origin_extrapolated ? 1 : cv::FILLED, cv::LINE_AA);
    cv::circle(img, view.ToPixel(f.landing_m.head<2>()), 5, FlightColour(f.index),
               f.landing_extrapolated ? 1 : cv::FILLED, cv::LINE_AA);
    Text(img, std::to_string(f.index), view.ToPixel(f.origin_m.head<2>()) + cv::Point2d(6, -6),
         kWhite);
  }
  if (decisions) {
    for (const auto& c : decisions->landings) {
      if (c.against != "playing area") continue;
      cv::circle(img, view.ToPixel(c.point_m), 7, c.in ? cv::Scalar(0, 255, 0) : kRed,
                 c.extrapolated ? 1 : 2, cv::LINE_AA);
    }
  }
  // Axes in metres, a scale bar and the legend.
  return field::FrameTopView(
      img, view,
      "top view. thick: seen part of a flight, thin: extrapolated; circles filled: seen, hollow: "
      "extrapolated (black origin, coloured landing); rings: landing in (green) / out (red); red "
      "x: outliers");
}

}  // namespace fv::recon
