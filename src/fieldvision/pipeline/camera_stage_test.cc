// The camera stage's tracking window: a ball that leaves the window where another accepted object
// lies is found again by a whole-frame search in that frame, not after full_scan_every frames;
// while tracking, bands of rows cover the whole frame every full_scan_every frames; the fusion's
// hints move the window off a better-scored static thing onto the ball (not off a track that
// follows the ball through a bounce they do not know of yet), a ball hidden from this camera alone
// is searched for in the whole frame every hidden_scan_every frames, and guided fits go on where
// the search finds no ball, for at most max_guided_frames frames.
#include "fieldvision/pipeline/camera_stage.h"

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"

namespace fv::pipeline {
namespace {

using Eigen::Vector2d;

struct Thing {
  Vector2d centre_px;
  double score;
};

// A scripted detector: the things of frame `f` that lie inside the searched region.
BallRegionDetectFn Scripted(const std::vector<std::vector<Thing>>* frames, const long long* f) {
  return [frames, f](const cv::Mat&, const cv::Rect& roi) {
    std::vector<recon::BallObservation> out;
    for (const Thing& t : (*frames)[*f]) {
      if (!roi.empty() && !roi.contains(cv::Point(static_cast<int>(t.centre_px.x()),
                                                  static_cast<int>(t.centre_px.y())))) {
        continue;
      }
      recon::BallObservation o;
      o.centre_px = t.centre_px;
      o.radius_px = 5.0;
      o.score = t.score;
      out.push_back(o);
    }
    return out;
  };
}

// A blank 640x480 frame numbered `f` through the stage (the scripted detectors ignore pixels).
CameraMessage ProcessBlank(CameraStage& stage, long long f) {
  io::SourceFrame in;
  in.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0));
  in.frame = f;
  return stage.Process(in);
}

TEST(CameraStage, ABallThatLeavesItsWindowIsSearchedForInTheWholeFrame) {
  const camera::Camera cam = camera::Camera::FromFov(640, 480, 60.0);
  // The ball rolls right at 10 px a frame, then bounces up at 40 px a frame: out of the window
  // around where it was expected. A static object (a cone, score lower) lies inside that window,
  // 25 px from where the ball was expected.
  std::vector<std::vector<Thing>> frames;
  const Vector2d cone(200, 265);
  Vector2d ball(100, 240);
  for (int f = 0; f < 16; ++f) {
    ball += f < 10 ? Vector2d(10, 0) : Vector2d(0, -12);
    if (f == 10) ball += Vector2d(-10, -48);
    frames.push_back({{ball, 0.9}, {cone, 0.5}});
  }
  long long f = 0;
  BallTrackOptions track;
  track.full_scan_every = 100;
  CameraStage stage(0, cam, Scripted(&frames, &f), track, "scripted");
  for (f = 0; f < static_cast<long long>(frames.size()); ++f) {
    const CameraMessage m = ProcessBlank(stage, f);
    const Vector2d& want = frames[f][0].centre_px;
    const bool has_ball = std::any_of(m.candidates.begin(), m.candidates.end(), [&](const auto& o) {
      return (o.centre_px - want).norm() < 1;
    });
    EXPECT_TRUE(has_ball) << "frame " << f << ": the ball at (" << want.transpose()
                          << ") is not among the " << m.candidates.size() << " candidates";
  }
  EXPECT_LT(stage.stats().full_scans, 4);  // the first frame, and where the ball jumped
}

TEST(CameraStage, WhileTrackingBandsCoverTheFrameAndFindAnotherBall) {
  const camera::Camera cam = camera::Camera::FromFov(640, 480, 60.0);
  // The ball rests at (320, 100); another ball-like object appears at frame 3 at (500, 430),
  // far outside the window. Every frame's searched regions are recorded.
  const Vector2d ball(320, 100), other(500, 430);
  std::vector<std::vector<Thing>> frames;
  for (int f = 0; f < 24; ++f) {
    frames.push_back({{ball, 0.9}});
    if (f >= 3) frames.back().push_back({other, 0.6});
  }
  long long f = 0;
  std::vector<std::vector<cv::Rect>> searched(frames.size());
  auto scripted = Scripted(&frames, &f);
  auto recording = [&](const cv::Mat& bgr, const cv::Rect& roi) {
    searched[f].push_back(roi);
    return scripted(bgr, roi);
  };
  BallTrackOptions track;
  track.full_scan_every = 8;
  track.scan_bands = 8;
  CameraStage stage(0, cam, recording, track, "scripted");
  long long first_seen = -1;
  for (f = 0; f < static_cast<long long>(frames.size()); ++f) {
    const CameraMessage m = ProcessBlank(stage, f);
    ASSERT_FALSE(m.candidates.empty()) << "frame " << f;
    EXPECT_NEAR((m.candidates[0].centre_px - ball).norm(), 0.0, 1e-9) << "frame " << f;
    const bool has_other = std::any_of(m.candidates.begin(), m.candidates.end(),
                                       [&](auto& o) { return (o.centre_px - other).norm() < 1; });
    if (has_other && first_seen < 0) first_seen = f;
    EXPECT_LE(m.candidates.size(), 2u) << "frame " << f << ": a ball reported twice";
  }
  EXPECT_EQ(stage.stats().full_scans, 1);  // the first frame only
  EXPECT_EQ(stage.stats().band_scans, 23);
  ASSERT_GE(first_seen, 3);
  EXPECT_LT(first_seen, 3 + 8) << "not found within one cover of the frame";
  // Any 8 frames in a row search one band each (besides the window): together every row, each band
  // a bounded share of the frame (480 / 8 rows plus 1.5 diameters of a ball twice the tracked one's
  // size, plus 4 px, each side: the scripted balls have a 5 px radius).
  std::vector<int> rows(480, 0);
  for (int g = 1; g <= 8; ++g) {
    ASSERT_EQ(searched[g].size(), 2u) << "frame " << g;
    const cv::Rect& band = searched[g][1];
    EXPECT_EQ(band.x, 0);
    EXPECT_EQ(band.width, 640);
    EXPECT_LE(band.height, 60 + 2 * 34) << "frame " << g;
    for (int y = band.y; y < band.y + band.height; ++y) ++rows[y];
  }
  EXPECT_EQ(std::count(rows.begin(), rows.end(), 0), 0) << "rows never searched";
}

TEST(CameraStage, TheWholeFrameSearchInTwoBandsTakesTwoFramesOfEachPeriod) {
  const camera::Camera cam = camera::Camera::FromFov(640, 480, 60.0);
  std::vector<std::vector<Thing>> frames(1 + 16, {{Vector2d(320, 100), 0.9}});
  long long f = 0;
  std::vector<cv::Rect> bands;
  auto scripted = Scripted(&frames, &f);
  auto recording = [&](const cv::Mat& bgr, const cv::Rect& roi) {
    if (!roi.empty() && roi.width == 640) bands.push_back(roi);
    return scripted(bgr, roi);
  };
  BallTrackOptions track;
  track.full_scan_every = 8;
  track.scan_bands = 2;
  CameraStage stage(0, cam, recording, track, "scripted");
  for (f = 0; f < static_cast<long long>(frames.size()); ++f) {
    ProcessBlank(stage, f);
  }
  EXPECT_EQ(stage.stats().full_scans, 1);
  ASSERT_EQ(bands.size(), 4u);  // two in each period of 8 frames after the first frame
  for (const cv::Rect& b : bands) EXPECT_LE(b.height, 240 + 2 * 34);
  EXPECT_EQ(std::min(bands[0].y, bands[1].y), 0);
  EXPECT_EQ(std::max(bands[0].y + bands[0].height, bands[1].y + bands[1].height), 480);
  EXPECT_GE(std::min(bands[0].y + bands[0].height, bands[1].y + bands[1].height),
            std::max(bands[0].y, bands[1].y) + 2 * 34);  // overlapping by the margins
}

TEST(CameraStage, CamerasSearchWholeFramesEveryFullScanEveryFramesEachAtItsOwnPhase) {
  // A resting ball, always found: besides the first frame, each camera searches the whole frame
  // once every 8 frames, and cameras of a rig mostly in different frames.
  std::vector<std::vector<Thing>> frames(33, {{Vector2d(320, 100), 0.9}});
  long long f = 0;
  BallTrackOptions track;
  track.full_scan_every = 8;
  std::vector<int> whole_in_frame(frames.size(), 0);
  for (const char* name : {"cam1", "cam2", "cam3", "cam4", "left", "right"}) {
    camera::Camera cam = camera::Camera::FromFov(640, 480, 60.0);
    cam.name = name;
    std::vector<long long> whole;
    auto scripted = Scripted(&frames, &f);
    auto recording = [&](const cv::Mat& bgr, const cv::Rect& roi) {
      if (roi.empty()) whole.push_back(f);
      return scripted(bgr, roi);
    };
    CameraStage stage(0, cam, recording, track, "scripted");
    for (f = 0; f < static_cast<long long>(frames.size()); ++f) {
      ProcessBlank(stage, f);
    }
    ASSERT_GE(whole.size(), 5u) << name;
    EXPECT_EQ(whole[0], 0) << name;
    EXPECT_LE(whole[1], 8) << name;
    for (size_t i = 2; i < whole.size(); ++i) EXPECT_EQ(whole[i] - whole[i - 1], 8) << name;
    for (size_t i = 1; i < whole.size(); ++i) ++whole_in_frame[whole[i]];
    EXPECT_EQ(stage.stats().full_scans, static_cast<long long>(whole.size()));
    EXPECT_EQ(stage.stats().band_scans, 0);
  }
  // 6 cameras in 8 phases: not all in one frame (at most 2 share one, for these names).
  EXPECT_LE(*std::max_element(whole_in_frame.begin() + 1, whole_in_frame.end()), 2);
}

// A posed 640x480 camera at the origin looking along +z, and the point 10 m deep at a pixel.
camera::Camera PosedCamera() {
  camera::Camera cam = camera::Camera::FromFov(640, 480, 60.0);
  cam.has_pose = true;
  return cam;
}
Eigen::Vector3d PointAt(const camera::Camera& cam, const Vector2d& px) {
  const auto ray = cam.RayFromPixel(px);
  return ray->At(10.0 / ray->direction.z());
}

TEST(CameraStage, TheFusionsHintsMoveTheWindowFromABetterScoredThingToTheBall) {
  // A seat scores higher than the ball; the first whole-frame search takes the seat, and the
  // window stays on it. The fusion knows the ball (it publishes the ball's 3D position seen
  // in the previous frame): with its hints the ball is among the candidates in every frame.
  const camera::Camera cam = PosedCamera();
  std::vector<std::vector<Thing>> frames;
  std::vector<Vector2d> ball;
  for (int f = 0; f < 20; ++f) {
    ball.emplace_back(100 + 6 * f, 300);
    frames.push_back({{Vector2d(500, 100), 0.9}, {ball.back(), 0.5}});
  }
  BallTrackOptions track;
  track.full_scan_every = 100;
  for (const bool hinted : {false, true}) {
    long long f = 0;
    CameraStage stage(0, cam, Scripted(&frames, &f), track, "scripted");
    BallHintBoard board(1, BallHintOptions{}, /*wait=*/false);
    if (hinted) stage.SetHints(&board);
    int with_ball = 0;
    for (f = 0; f < static_cast<long long>(frames.size()); ++f) {
      if (f > 0) board.Publish((f - 1) / 60.0, PointAt(cam, ball[f - 1]), 0.11);
      io::SourceFrame in;
      in.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0));
      in.frame = f;
      in.time_s = f / 60.0;
      const CameraMessage m = stage.Process(in);
      with_ball += std::any_of(m.candidates.begin(), m.candidates.end(),
                               [&](const auto& o) { return (o.centre_px - ball[f]).norm() < 1; });
    }
    if (hinted) {
      EXPECT_EQ(with_ball, 20);
    } else {
      EXPECT_LE(with_ball, 2);  // the first whole-frame search only
    }
  }
}

// A still thing of the ball's colour in view for 40 frames; from frame 10 the ball too, better
// scored, away from it.
std::vector<std::vector<Thing>> StillThingThenBall() {
  std::vector<std::vector<Thing>> frames;
  for (int f = 0; f < 40; ++f) {
    frames.push_back({{Vector2d(500, 100), 0.2}});
    if (f >= 10) frames.back().push_back({Vector2d(100 + 6 * f, 300), 0.9});
  }
  return frames;
}

// The first frame whose message has the ball of StillThingThenBall (-1: none); `before` is called
// with each frame number before it is processed.
long long FirstFrameWithTheBall(CameraStage& stage, const std::vector<std::vector<Thing>>& frames,
                                long long* f, const std::function<void(long long)>& before) {
  long long first_ball = -1;
  for (*f = 0; *f < static_cast<long long>(frames.size()); ++*f) {
    before(*f);
    io::SourceFrame in;
    in.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0));
    in.frame = *f;
    in.time_s = *f / 60.0;
    const CameraMessage m = stage.Process(in);
    const bool ball = std::any_of(m.candidates.begin(), m.candidates.end(),
                                  [](const auto& o) { return o.centre_px.y() == 300; });
    if (ball && first_ball < 0) first_ball = *f;
  }
  return first_ball;
}

TEST(CameraStage, WithoutAFusedPositionAStillThingGivesWayToTheBallWithinUnconfirmedScanEvery) {
  // The ball is hidden from this camera for 10 frames while a still thing of its colour is in
  // view; the window settles on the thing. From frame 10 the ball is in view, better scored, away
  // from the window. The cameras together have no position (nothing published): with hints the
  // whole frame is searched every unconfirmed_scan_every frames and the ball is found by frame
  // 10 + 5; without hints (or with 0) only at the full_scan_every slot.
  const camera::Camera cam = PosedCamera();
  const std::vector<std::vector<Thing>> frames = StillThingThenBall();
  BallTrackOptions track;
  track.full_scan_every = 100;
  for (const int every : {0, 5}) {
    track.unconfirmed_scan_every = every;
    long long f = 0;
    CameraStage stage(0, cam, Scripted(&frames, &f), track, "scripted");
    BallHintBoard board(1, BallHintOptions{}, /*wait=*/false);
    stage.SetHints(&board);
    const long long first_ball = FirstFrameWithTheBall(stage, frames, &f, [](long long) {});
    if (every == 5) {
      EXPECT_GE(first_ball, 10);
      EXPECT_LE(first_ball, 15);
      EXPECT_LE(stage.stats().full_scans, 40 / 5 + 2);  // and the first frame, the switch
    } else {
      EXPECT_EQ(first_ball, -1);  // the slot of full_scan_every 100 never comes
    }
  }
  track.unconfirmed_scan_every = -1;
  EXPECT_THROW(track.Check(), Error);
}

// A camera node (no_hint_means_unconfirmed false) searches whole for want of a position only once
// the fusion node has told of a frame without one (a lost hint), and then on frame numbers that
// are multiples of unconfirmed_scan_every, so that the nodes search the same frames.
TEST(CameraStage, ANodeSearchesWholeOnAlignedFramesOnceTheFusionTellsOfLoss) {
  const camera::Camera cam = PosedCamera();
  const std::vector<std::vector<Thing>> frames = StillThingThenBall();
  BallTrackOptions track;
  track.full_scan_every = 100;
  track.unconfirmed_scan_every = 5;
  for (const bool tells : {false, true}) {
    long long f = 0;
    CameraStage stage(0, cam, Scripted(&frames, &f), track, "scripted");
    BallHintBoard board(1, BallHintOptions{}, /*wait=*/false);
    stage.SetHints(&board, /*no_hint_means_unconfirmed=*/false);
    const long long first_ball = FirstFrameWithTheBall(stage, frames, &f, [&](long long k) {
      if (tells && k == 3) board.MarkTellsLoss();
    });
    // Told: the first whole search from frame 10 on falls on frame 10 (a multiple of 5).
    EXPECT_EQ(first_ball, tells ? 10 : -1) << (tells ? "told of loss" : "never told");
  }
}

// What a stage did with the fusion's hints: the fusion publishes the ball of frame f - 2 (the
// offline hints' lag; seen by the other cameras) before this camera's frame f.
struct HintedRun {
  std::vector<long long> whole;      // frames searched whole
  std::vector<long long> with_ball;  // frames whose message has the ball
};
HintedRun RunHinted(const std::vector<std::vector<Thing>>& frames,
                    const std::vector<Vector2d>& ball, const BallTrackOptions& track) {
  const camera::Camera cam = PosedCamera();
  HintedRun run;
  long long f = 0;
  auto scripted = Scripted(&frames, &f);
  auto recording = [&](const cv::Mat& bgr, const cv::Rect& roi) {
    if (roi.empty()) run.whole.push_back(f);
    return scripted(bgr, roi);
  };
  CameraStage stage(0, cam, recording, track, "scripted");
  BallHintBoard board(1, BallHintOptions{}, /*wait=*/false);
  stage.SetHints(&board);
  for (f = 0; f < static_cast<long long>(frames.size()); ++f) {
    if (f >= 2) board.Publish((f - 2) / 60.0, PointAt(cam, ball[f - 2]), 0.11);
    io::SourceFrame in;
    in.bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0));
    in.frame = f;
    in.time_s = f / 60.0;
    const CameraMessage m = stage.Process(in);
    if (std::any_of(m.candidates.begin(), m.candidates.end(),
                    [&](const auto& o) { return (o.centre_px - ball[f]).norm() < 1; })) {
      run.with_ball.push_back(f);
    }
  }
  return run;
}

std::vector<long long> Frames(long long from, long long to, long long except = -1) {
  std::vector<long long> out;
  for (long long f = from; f < to; ++f) {
    if (f != except) out.push_back(f);
  }
  return out;
}

TEST(CameraStage, ATrackOnTheBallWhenTheCamerasLastSawItKeepsItsWindowThroughABounce) {
  // The ball rolls right, then from frame 10 also up the image (a bounce). The fusion's hints,
  // two frames late, expect it to go on straight for two frames; the camera's own track, which
  // was on the ball at the hints' times, follows it: no window moved off the ball, no frame
  // searched whole but the first.
  std::vector<std::vector<Thing>> frames;
  std::vector<Vector2d> ball;
  for (int f = 0; f < 20; ++f) {
    ball.push_back(f == 0 ? Vector2d(100, 300)
                          : Vector2d(ball.back() + (f <= 9 ? Vector2d(6, 0) : Vector2d(6, -10))));
    frames.push_back({{ball.back(), 0.8}});
  }
  BallTrackOptions track;
  track.full_scan_every = 100;
  const HintedRun run = RunHinted(frames, ball, track);
  EXPECT_EQ(run.with_ball, Frames(0, 20));
  EXPECT_EQ(run.whole, std::vector<long long>{0});
}

TEST(CameraStage, ATrackThatJumpedToAnotherThingIsSteeredBackToTheBall) {
  // The ball, hidden from this camera in frame 10 only, is seen by the others throughout; the
  // whole-frame search of frame 10 takes a better-scored seat that came into view. The track was
  // on the ball at the hints' time (frame 9), but then jumped: the hint moves its window back to
  // the ball in frame 11.
  std::vector<std::vector<Thing>> frames;
  std::vector<Vector2d> ball;
  for (int f = 0; f < 20; ++f) {
    ball.emplace_back(100 + 5 * f, 300);
    frames.emplace_back();
    if (f != 10) frames.back().push_back({ball.back(), 0.5});
    if (f >= 10) frames.back().push_back({Vector2d(500, 100), 0.9});
  }
  BallTrackOptions track;
  track.full_scan_every = 100;
  const HintedRun run = RunHinted(frames, ball, track);
  EXPECT_EQ(run.with_ball, Frames(0, 20, /*except=*/10));
  EXPECT_EQ(run.whole, (std::vector<long long>{0, 10}));  // not 11: the window went to the ball
}

TEST(CameraStage, ABallHiddenFromThisCameraOnlyIsSearchedWholeEveryHiddenScanEveryFrames) {
  // The ball rolls; the other cameras see it throughout, this one not in frames 5-24 (behind a
  // robot), while a still thing of its colour is in view. A whole-frame search finds only the
  // thing: after the first hidden frame, the whole frame is searched every hidden_scan_every
  // frames; the window stays where the others see the ball and finds it in frame 25.
  std::vector<std::vector<Thing>> frames;
  std::vector<Vector2d> ball;
  for (int f = 0; f < 35; ++f) {
    ball.emplace_back(100 + 5 * f, 300);
    frames.push_back({{Vector2d(500, 100), 0.2}});
    if (f < 5 || f >= 25) frames.back().push_back({ball.back(), 0.8});
  }
  BallTrackOptions track;
  track.full_scan_every = 100;
  for (const int every : {0, 5}) {
    track.hidden_scan_every = every;
    const HintedRun run = RunHinted(frames, ball, track);
    std::vector<long long> visible = Frames(0, 5);
    for (long long f : Frames(25, 35)) visible.push_back(f);
    EXPECT_EQ(run.with_ball, visible) << "hidden_scan_every " << every;
    // Frames 5 and 6 whole: the hints are of frames 3 and 4, where this camera saw the ball.
    std::vector<long long> whole{0, 5, 6};
    for (long long f : Frames(7, 25)) {
      if (every == 0 || (f - 7) % every == 0) whole.push_back(f);
    }
    EXPECT_EQ(run.whole, whole) << "hidden_scan_every " << every;
  }
  track.hidden_scan_every = -1;
  EXPECT_THROW(track.Check(), Error);
}

TEST(CameraStage, ABallAtANewPlaceEachFrameIsNotHiddenAndIsSearchedForWhole) {
  // The fused positions jump between far places every frame (no line through them: the hints
  // have no track), and this camera misses the ball until frame 10: not hidden from it, so each
  // frame whose window misses is searched whole, and the ball is found from frame 10 on.
  std::vector<std::vector<Thing>> frames;
  std::vector<Vector2d> ball;
  for (int f = 0; f < 20; ++f) {
    ball.emplace_back(100 + 200 * (f % 3), 100 + 150 * ((f / 3) % 2));
    frames.push_back({{Vector2d(600, 450), 0.2}});
    if (f >= 10) frames.back().push_back({ball.back(), 0.8});
  }
  BallTrackOptions track;
  track.full_scan_every = 100;
  const HintedRun run = RunHinted(frames, ball, track);
  EXPECT_EQ(run.with_ball, Frames(10, 20));
  // Frame 1: no hint yet, the window on the still thing the first search took.
  EXPECT_EQ(run.whole, Frames(0, 20, /*except=*/1));
}

TEST(CameraStage, GuidedFitsGoOnWhereTheSearchLosesTheBallForMaxGuidedFrames) {
  // The ball rolls right; from frame 5 the search no longer finds it (merged with a board).
  // A guided fit at the expected place finds it there for max_guided_frames frames in a row.
  const camera::Camera cam = PosedCamera();
  std::vector<std::vector<Thing>> frames;
  std::vector<Vector2d> ball;
  for (int f = 0; f < 15; ++f) {
    ball.emplace_back(100 + 5 * f, 200);
    frames.push_back(f < 5 ? std::vector<Thing>{{ball.back(), 0.8}} : std::vector<Thing>{});
  }
  long long f = 0;
  std::vector<long long> asked;
  BallGuidedFn guided = [&](const cv::Mat&, const cv::Rect& roi, const Vector2d& centre_px,
                            double radius_px) -> std::optional<recon::BallObservation> {
    asked.push_back(f);
    EXPECT_TRUE(roi.contains(cv::Point(int(centre_px.x()), int(centre_px.y()))));
    EXPECT_NEAR(radius_px, 5.0, 1e-9);
    if ((centre_px - ball[f]).norm() > 3.0) return std::nullopt;
    recon::BallObservation o;
    o.centre_px = ball[f];
    o.radius_px = 5.0;
    o.score = 0.3;
    return o;
  };
  BallTrackOptions track;
  track.full_scan_every = 100;
  track.max_guided_frames = 4;
  CameraStage stage(0, cam, Scripted(&frames, &f), track, "scripted", guided);
  std::vector<long long> with_ball;
  for (f = 0; f < static_cast<long long>(frames.size()); ++f) {
    const CameraMessage m = ProcessBlank(stage, f);
    for (const recon::BallObservation& o : m.candidates) {
      if ((o.centre_px - ball[f]).norm() < 1) with_ball.push_back(f);
    }
  }
  EXPECT_EQ(with_ball, (std::vector<long long>{0, 1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(asked, (std::vector<long long>{5, 6, 7, 8}));  // then the track is lost
  EXPECT_EQ(stage.stats().guided, 4);
}

}  // namespace
}  // namespace fv::pipeline
