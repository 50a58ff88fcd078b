// The offline flight refinement piece by piece: two kicks a second apart are refined as the whole
// track would be, the first piece's candidates are dropped once the second starts, and bad
// options and out-of-order positions are named.
#include "fieldvision/pipeline/flight_refiner.h"

#include <gtest/gtest.h>

#include "fieldvision/pipeline/test_messages.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::pipeline {
namespace {

using test_util::CornerRig;

struct Clip {
  std::vector<CameraMessage> messages;  // per frame, each camera's, in time order
  std::vector<recon::BallSample> per_frame;
  long long first_flight_messages = 0;
};

// Two kicks from the ground at 60 fps, 1 s apart: the ball seen in every camera with 1 px noise
// (and a false candidate in camera 0), each frame's position 2 cm off at random.
Clip TwoKicks(const std::vector<camera::Camera>& cams, util::Rng& rng) {
  Clip clip;
  const double starts_s[] = {0.0, 1.8};
  const Eigen::Vector3d p0[] = {{-4, -1, 0.11}, {3, 2, 0.11}};
  const Eigen::Vector3d v0[] = {{7, 1, 4}, {-6, -2, 5}};
  long long frame = 0;
  for (int k = 0; k < 2; ++k) {
    for (int i = 0; i < 45; ++i, ++frame) {
      const double dt = i / 60.0;
      const Eigen::Vector3d p = p0[k] + v0[k] * dt + Eigen::Vector3d(0, 0, -4.905 * dt * dt);
      const double t = starts_s[k] + dt;
      for (int c = 0; c < 4; ++c) {
        CameraMessage m;
        m.camera = c;
        m.frame = frame;
        m.time_s = t;
        recon::BallObservation o;
        o.centre_px = *cams[c].Project(p) + Eigen::Vector2d(rng.Normal(0, 1), rng.Normal(0, 1));
        o.radius_px = 8;
        m.candidates.push_back(o);
        if (c == 0) {
          o.centre_px = {rng.Uniform(0, 1280), rng.Uniform(0, 960)};
          m.candidates.push_back(o);
        }
        clip.messages.push_back(m);
        clip.first_flight_messages += k == 0;
      }
      recon::BallSample s;
      s.frame = frame;
      s.time_s = t;
      s.ball_in_world = p + Eigen::Vector3d(rng.Normal(0, 0.02), rng.Normal(0, 0.02), 0);
      s.n_cams = 4;
      clip.per_frame.push_back(s);
    }
  }
  return clip;
}

TEST(FlightRefiner, PiecesAsTheWholeTrackAndTheFirstPieceDropped) {
  const uint64_t seed = testing::TestSeed(71);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const auto cams = CornerRig();
  const Clip clip = TwoKicks(cams, rng);

  // The whole track at once.
  std::vector<std::vector<CameraMessage>> by_camera(cams.size());
  for (const auto& m : clip.messages) by_camera[m.camera].push_back(m);
  std::vector<recon::BallSample> whole = clip.per_frame;
  const FlightBundle all = BundleFlights(cams, by_camera, 0.22, 0.0, 2.0, &whole);
  ASSERT_EQ(all.bundled_flights, 2);

  std::vector<recon::BallSample> rows;
  FlightRefiner refiner(cams, {}, [&](const recon::BallSample& s) { rows.push_back(s); });
  size_t next = 0;
  long long held_at_second = -1;
  for (const auto& s : clip.per_frame) {
    while (next < clip.messages.size() && clip.messages[next].time_s <= s.time_s) {
      refiner.AddMessage(clip.messages[next++]);
    }
    refiner.AddSample(s);
    if (s.time_s >= 1.8 && held_at_second < 0) held_at_second = refiner.held_messages();
  }
  while (next < clip.messages.size()) refiner.AddMessage(clip.messages[next++]);
  // The first kick is written as soon as the second starts, and its candidates are gone.
  EXPECT_EQ(refiner.pieces(), 1);
  EXPECT_EQ(rows.size(), 45u);
  EXPECT_LE(held_at_second, 4);
  refiner.Finish();
  EXPECT_EQ(refiner.pieces(), 2);
  EXPECT_EQ(refiner.totals().bundled_flights, 2);
  EXPECT_EQ(refiner.totals().bundled_rows, all.bundled_rows);
  EXPECT_EQ(refiner.held_messages(), 0);
  ASSERT_EQ(rows.size(), whole.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].frame, whole[i].frame);
    EXPECT_LT((rows[i].ball_in_world - whole[i].ball_in_world).norm(), 1e-3) << "frame " << i;
  }
}

// A hop that lands and rolls on just before the track ends (the low-sun kick's end): the frames
// after the landing are too few for a ground phase of their own, the first of them was left in
// the hop's arc and its model carried on through the ground there; a ball cannot be below the
// ground, so those rows keep their own positions.
TEST(FlightRefiner, NoRowGoesBelowTheGroundAfterTheLastLanding) {
  const auto cams = CornerRig();
  int checked = 0;
  for (uint64_t k = 0; k < 6; ++k) {
    const uint64_t seed = testing::TestSeed(31) + k;
    FV_SEED_TRACE(seed);
    util::Rng rng(seed);
    // A kick, a bounce and a low hop (0.15-0.25 m high) after it: one frame after the hop lands its
    // parabola is only 2-3 cm below the ground, within the noise a track's last samples are
    // judged by.
    const Eigen::Vector3d p0(-4, -1, 0.11), v0(6, 1, 4.0);
    const double t_bounce = 2 * v0.z() / 9.81;
    const Eigen::Vector3d p1 =
        p0 + v0 * t_bounce + Eigen::Vector3d(0, 0, -4.905 * t_bounce * t_bounce);
    const Eigen::Vector3d v1(0.8 * v0.x(), 0.8 * v0.y(), rng.Uniform(1.7, 2.2));
    const double t_land = t_bounce + 2 * v1.z() / 9.81;
    std::vector<std::vector<CameraMessage>> by_camera(cams.size());
    std::vector<recon::BallSample> track;
    // Frames 1/60 s apart, the last two 0.01 and 0.027 s after landing.
    const int before = static_cast<int>(std::floor((t_land + 0.01) * 60));
    for (int f = 0; f <= before + 1; ++f) {
      const double t = t_land + 0.01 + (f - before) / 60.0;
      const double u = t - t_bounce;
      Eigen::Vector3d p =
          t < t_bounce ? Eigen::Vector3d(p0 + v0 * t + Eigen::Vector3d(0, 0, -4.905 * t * t))
                       : Eigen::Vector3d(p1 + v1 * u + Eigen::Vector3d(0, 0, -4.905 * u * u));
      if (t > t_land) {  // rolling on
        p = p1 + v1 * (t_land - t_bounce) + Eigen::Vector3d(v1.x(), v1.y(), 0) * (t - t_land);
        p.z() = 0.11;
      }
      for (size_t c = 0; c < cams.size(); ++c) {
        CameraMessage m;
        m.camera = static_cast<int>(c);
        m.frame = f;
        m.time_s = t;
        recon::BallObservation o;
        o.centre_px = *cams[c].Project(p) + Eigen::Vector2d(rng.Normal(0, 0.3), rng.Normal(0, 0.3));
        m.candidates.push_back(o);
        by_camera[c].push_back(m);
      }
      recon::BallSample s;
      s.frame = f;
      s.time_s = t;
      s.ball_in_world =
          p + Eigen::Vector3d(rng.Normal(0, 0.004), rng.Normal(0, 0.004), rng.Normal(0, 0.003));
      s.n_cams = 4;
      track.push_back(s);
    }
    const std::vector<recon::BallSample> per_frame = track;
    const FlightBundle b = BundleFlights(cams, by_camera, 0.22, 0.0, 2.0, &track);
    ASSERT_GE(b.bundled_flights, 1);
    for (size_t i = 0; i < track.size(); ++i) {
      EXPECT_GE(track[i].ball_in_world.z(), 0.11 - 0.01) << "frame " << i;
      if (track[i].time_s > t_land) {
        ++checked;
        EXPECT_LT((track[i].ball_in_world - per_frame[i].ball_in_world).norm(), 0.05) << i;
      }
    }
  }
  EXPECT_GE(checked, 6);
}

TEST(FlightRefiner, BadOptionsAndOutOfOrderPositionsAreNamed) {
  const auto cams = CornerRig();
  const auto expect_named = [&](const FlightRefinerOptions& o, const std::string& field) {
    try {
      const FlightRefiner refiner(cams, o, [](const recon::BallSample&) {});
      ADD_FAILURE() << field << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  FlightRefinerOptions o;
  o.gap_s = 0.1;  // shorter than a flight may go unseen: a flight could span a cut
  expect_named(o, "gap_s");
  o = {};
  o.sigma_px = 0;
  expect_named(o, "sigma_px");
  o = {};
  o.max_piece_s = 0.2;
  expect_named(o, "max_piece_s");

  FlightRefiner refiner(cams, {}, [](const recon::BallSample&) {});
  recon::BallSample s;
  s.time_s = 1.0;
  refiner.AddSample(s);
  s.time_s = 0.5;
  EXPECT_THROW(refiner.AddSample(s), Error);
  CameraMessage m;
  m.camera = 4;
  EXPECT_THROW(refiner.AddMessage(m), Error);
}

}  // namespace
}  // namespace fv::pipeline
