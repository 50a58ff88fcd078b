#include "fieldvision/pipeline/ball_hints.h"

#include <algorithm>
#include <cmath>

#include "fieldvision/camera/sphere_image.h"
#include "fieldvision/util/error.h"

namespace fv::pipeline {
namespace {

constexpr double kGravityMps2 = 9.81;

// Where a hinted ball is `age_s` after its time.
Eigen::Vector3d BallAfter(const BallHint& h, double age_s) {
  Eigen::Vector3d p = h.ball_in_world + age_s * h.velocity_mps;
  if (h.airborne) p.z() -= 0.5 * kGravityMps2 * age_s * age_s;
  return p;
}

// A line through (tau, x) (tau: time from the newest position) by least squares, its value and
// slope at tau = 0; `use` selects the positions.
void FitLine(const std::vector<double>& tau, const std::vector<Eigen::Vector3d>& x,
             const std::vector<char>& use, Eigen::Vector3d* at0, Eigen::Vector3d* slope) {
  double n = 0, st = 0, stt = 0;
  Eigen::Vector3d sx = Eigen::Vector3d::Zero(), stx = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < tau.size(); ++i) {
    if (!use[i]) continue;
    n += 1;
    st += tau[i];
    stt += tau[i] * tau[i];
    sx += x[i];
    stx += tau[i] * x[i];
  }
  const double den = n * stt - st * st;
  *slope = den > 1e-12 ? Eigen::Vector3d((n * stx - st * sx) / den) : Eigen::Vector3d::Zero();
  *at0 = (sx - *slope * st) / n;
}

}  // namespace

BallHint FitHint(const std::deque<std::pair<double, Eigen::Vector3d>>& recent, double radius_m,
                 const BallHintOptions& o) {
  BallHint h;
  h.radius_m = radius_m;
  h.time_s = recent.back().first;
  h.ball_in_world = recent.back().second;
  if (recent.size() < 2) return h;
  const double flying_z = radius_m + o.airborne_m;
  h.airborne = std::all_of(recent.begin(), recent.end(),
                           [&](const auto& r) { return r.second.z() > flying_z; });
  // In flight z + g tau^2 / 2 is a line in tau.
  std::vector<double> tau;
  std::vector<Eigen::Vector3d> x;
  for (const auto& [t, p] : recent) {
    tau.push_back(t - h.time_s);
    x.push_back(p);
    if (h.airborne) x.back().z() += 0.5 * kGravityMps2 * tau.back() * tau.back();
  }
  std::vector<char> use(x.size(), 1);
  Eigen::Vector3d at0, v;
  // Against the line of the older positions: the two newest both off it, the ball was kicked
  // (the new line is theirs); the newest alone, it is on another object (dropped).
  const size_t last = x.size() - 1;
  if (last >= 3) {
    std::vector<char> older(x.size(), 1);
    older[last] = older[last - 1] = 0;
    FitLine(tau, x, older, &at0, &v);
    const auto off = [&](size_t i) { return (x[i] - (at0 + tau[i] * v)).norm() > o.outlier_m; };
    if (off(last) && off(last - 1)) {
      use = std::vector<char>(x.size(), 0);
      use[last] = use[last - 1] = 1;
    } else if (off(last)) {
      use[last] = 0;
    }
  }
  // Then the worst one dropped while it is off the line and more than two remain. When that leaves
  // two, which were off is a guess (of three evenly spaced positions the middle one is always the
  // one dropped: on another object, or the ball at three places far apart): the newest position
  // kept, alone, without velocity.
  int dropped = 0;
  for (auto left = std::count(use.begin(), use.end(), 1);; --left) {
    FitLine(tau, x, use, &at0, &v);
    if (left <= 2) break;
    size_t worst = 0;
    double worst_m = -1;
    for (size_t i = 0; i < x.size(); ++i) {
      const double d = use[i] ? (x[i] - (at0 + tau[i] * v)).norm() : -1.0;
      if (d > worst_m) {
        worst_m = d;
        worst = i;
      }
    }
    if (worst_m <= o.outlier_m) break;
    use[worst] = 0;
    ++dropped;
  }
  const int kept = static_cast<int>(std::count(use.begin(), use.end(), 1));
  if (dropped > 0 && kept <= 2) {
    const size_t from_end =
        static_cast<size_t>(std::find(use.rbegin(), use.rend(), 1) - use.rbegin());
    const auto& [t_s, p] = recent[recent.size() - 1 - from_end];
    h.time_s = t_s;
    h.ball_in_world = p;
    h.airborne = false;
    return h;
  }
  if (v.norm() > o.max_speed_mps) {
    h.airborne = false;
    return h;  // a jump between objects: no velocity
  }
  h.ball_in_world = at0;
  h.velocity_mps = v;
  h.positions = kept;
  return h;
}

void BallHintOptions::Check() const {
  FV_REQUIRE(lag_messages >= 1, "BallHintOptions.lag_messages must be >= 1 (got {})", lag_messages);
  CheckPositive(max_age_s, "BallHintOptions.max_age_s");
  CheckPositive(max_gap_s, "BallHintOptions.max_gap_s");
  CheckPositive(max_speed_mps, "BallHintOptions.max_speed_mps");
  CheckNonNegative(airborne_m, "BallHintOptions.airborne_m");
  CheckPositive(fit_span_s, "BallHintOptions.fit_span_s");
  CheckPositive(outlier_m, "BallHintOptions.outlier_m");
}

std::optional<ExpectedBall> ExpectBall(const BallHint& hint, const camera::Camera& camera,
                                       double time_s, double frame_dt_s,
                                       const BallHintOptions& options) {
  const double age_s = time_s - hint.time_s;
  if (!(age_s >= 0.0 && age_s <= options.max_age_s) || !camera.has_pose) return std::nullopt;
  const Eigen::Vector3d at = BallAfter(hint, age_s);
  const std::optional<Eigen::Vector2d> uv = camera.Project(at);
  if (!uv || !uv->allFinite() || !camera.InImage(*uv)) return std::nullopt;
  const Eigen::Vector3d in_cam = camera.cam_from_world * at;
  if (in_cam.z() <= hint.radius_m) return std::nullopt;
  ExpectedBall e;
  e.centre_px = *uv;
  const std::optional<double> radius_px = camera::SphereRadiusPx(camera, at, hint.radius_m);
  if (!radius_px) return std::nullopt;
  e.radius_px = *radius_px;
  const std::optional<Eigen::Vector2d> before =
      camera.Project(BallAfter(hint, age_s - std::max(frame_dt_s, 0.0)));
  if (before && before->allFinite()) e.step_px = *uv - *before;
  if (!std::isfinite(e.radius_px) || !e.step_px.allFinite()) return std::nullopt;
  return e;
}

BallHintBoard::BallHintBoard(int cameras, const BallHintOptions& options, bool wait)
    : options_(options), wait_(wait), popped_(cameras, 0), at_pop_(cameras) {
  options_.Check();
  FV_REQUIRE(cameras >= 1, "ball hints: no cameras");
}

void BallHintBoard::Publish(double time_s, const Eigen::Vector3d& ball_in_world, double radius_m) {
  if (!std::isfinite(time_s) || !ball_in_world.allFinite()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (!recent_.empty() &&
      (time_s <= recent_.back().first || time_s - recent_.back().first > options_.max_gap_s)) {
    recent_.clear();  // out of order or after a gap: a new track
  }
  recent_.emplace_back(time_s, ball_in_world);
  while (time_s - recent_.front().first > options_.fit_span_s + 1e-9) recent_.pop_front();
  state_ = FitHint(recent_, radius_m, options_);
}

void BallHintBoard::Popped(int camera) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++popped_.at(camera);
    auto& q = at_pop_[camera];
    q.push_back(state_);
    while (q.size() > static_cast<size_t>(options_.lag_messages) + 1) q.pop_front();
  }
  changed_.notify_all();
}

std::optional<BallHint> BallHintBoard::Get(int camera, long long index) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!wait_) return state_;
  const long long want = index - options_.lag_messages;  // the message whose pop counts
  if (want < 0) return std::nullopt;
  changed_.wait(lock, [&] { return closed_ || popped_.at(camera) > want; });
  if (closed_) return std::nullopt;
  // popped_ - 1 is the back of at_pop_; a stage is never more than lag messages ahead.
  const auto& q = at_pop_[camera];
  const long long back = popped_[camera] - 1;
  const long long from_back = back - want;
  if (from_back < 0 || from_back >= static_cast<long long>(q.size())) return std::nullopt;
  return q[q.size() - 1 - static_cast<size_t>(from_back)];
}

void BallHintBoard::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

}  // namespace fv::pipeline
