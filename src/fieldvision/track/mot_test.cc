#include "fieldvision/track/mot.h"
#include "fieldvision/track/mot_internal.h"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// Random walkers: `people` tracks over `frames` frames.
std::vector<TrackRow> Walkers(util::Rng& rng, int people, int frames) {
  std::vector<TrackRow> rows;
  for (int p = 0; p < people; ++p) {
    double x = rng.Uniform(0, 600), y = rng.Uniform(0, 400);
    const double vx = rng.Uniform(-3, 3), vy = rng.Uniform(-2, 2);
    for (int f = 0; f < frames; ++f) {
      rows.push_back({f, p + 1, cv::Rect2d(x + vx * f, y + vy * f, 30, 80), 1.0, {}, {}});
    }
  }
  return rows;
}

TEST(Mot, PerfectTracksScoreOne) {
  fv::testing::SeededRng rng(3);
  const auto gt = Walkers(rng, 5, 50);
  auto est = gt;
  for (auto& r : est) r.id += 100;  // ids need not be equal
  const MotMetrics m = EvaluateMot(gt, est);
  EXPECT_DOUBLE_EQ(m.mota, 1.0);
  EXPECT_DOUBLE_EQ(m.idf1, 1.0);
  EXPECT_NEAR(m.hota, 1.0, 1e-9);
  EXPECT_NEAR(m.motp, 1.0, 1e-9);
  EXPECT_EQ(m.id_switches, 0);
  EXPECT_EQ(m.tp, 250);
}

// An estimate of a clip (the first 20 of 50 frames) scored against the whole video's ground
// truth: the frames after it count as misses and the summary says so; clip_to_est_frames scores
// the clip's frames only.
TEST(Mot, AnEstimateOfAClipIsNotedOrScoredOverItsFrames) {
  fv::testing::SeededRng rng(4);
  const auto gt = Walkers(rng, 5, 50);
  std::vector<TrackRow> clip;
  for (const auto& r : gt) {
    if (r.frame >= 5 && r.frame < 20) clip.push_back(r);
  }
  MotOptions o;
  const MotMetrics whole = EvaluateMot(gt, clip, o);
  EXPECT_EQ(whole.preprocessing.gt_outside_est_frames, 5 * 35);
  EXPECT_NEAR(whole.recall, 0.3, 1e-9);
  EXPECT_THAT(whole.preprocessing.Summary(), HasSubstr("covers frames 5..19 only"));
  o.clip_to_est_frames = true;
  const MotMetrics scored = EvaluateMot(gt, clip, o);
  EXPECT_DOUBLE_EQ(scored.mota, 1.0);
  EXPECT_EQ(scored.frames, 15);
  EXPECT_THAT(scored.preprocessing.Summary(), ::testing::Not(HasSubstr("NOTE")));
  // What else is scored on the ground truth (eval tracks: positions, the coach's numbers) takes
  // the same frames; without the option all of them.
  std::vector<TrackRow> as_scored = gt, est_scored = clip;
  scored.preprocessing.ClipAsScored(as_scored, est_scored, 0);
  EXPECT_EQ(as_scored.size(), 5u * 15);
  for (const auto& r : as_scored) EXPECT_TRUE(r.frame >= 5 && r.frame < 20) << r.frame;
  EXPECT_EQ(est_scored.size(), clip.size());
  as_scored = gt;
  whole.preprocessing.ClipAsScored(as_scored, est_scored, 0);
  EXPECT_EQ(as_scored.size(), gt.size());
  // And the estimate's rows outside the ground truth's frames (a ground truth of part of the
  // video): the ground truth of frames 5..19 against tracks of all 50 frames, 1-based tracks
  // scored with an offset of -1.
  std::vector<TrackRow> shifted = gt;
  for (auto& r : shifted) r.frame += 1;
  MotOptions offset;
  offset.frame_offset = -1;
  const MotMetrics part = EvaluateMot(clip, shifted, offset);
  EXPECT_DOUBLE_EQ(part.mota, 1.0);
  std::vector<TrackRow> part_gt = clip, part_est = shifted;
  part.preprocessing.ClipAsScored(part_gt, part_est, offset.frame_offset);
  EXPECT_EQ(part_gt.size(), clip.size());
  EXPECT_EQ(part_est.size(), 5u * 15);
  for (const auto& r : part_est) EXPECT_TRUE(r.frame >= 6 && r.frame < 21) << r.frame;
  EXPECT_EQ(EvaluateMot(gt, gt, o).preprocessing.gt_outside_est_frames, 0);
  // A tracker's warm-up (nothing in the first 3 of 50 frames) is no clip: no note.
  std::vector<TrackRow> late;
  for (const auto& r : gt) {
    if (r.frame >= 3) late.push_back(r);
  }
  EXPECT_THAT(EvaluateMot(gt, late).preprocessing.Summary(), ::testing::Not(HasSubstr("NOTE")));
}

// Tracks of other frames (another video's, a wrong frame offset) share no frame with the ground
// truth: an error saying so, not scores of 0 that read as a tracker that found nobody.
TEST(Mot, EstimatesInNoFrameOfTheGroundTruthAreAnError) {
  fv::testing::SeededRng rng(5);
  const auto gt = Walkers(rng, 3, 20);
  auto est = gt;
  for (auto& r : est) r.frame += 1000;
  EXPECT_THAT([&] { EvaluateMot(gt, est); },
              ThrowsMessage<Error>(
                  ::testing::AllOf(HasSubstr("frames 0..19"), HasSubstr("frames 1000..1019"))));
  EXPECT_EQ(EvaluateMot(gt, {}).tp, 0);  // no estimate at all: scored, all misses
}

TEST(Mot, CountsMissesFalsePositivesAndSwitches) {
  fv::testing::SeededRng rng(4);
  const int frames = 40;
  const auto gt = Walkers(rng, 3, frames);
  std::vector<TrackRow> est;
  int dropped = 0;
  for (auto r : gt) {
    if (r.id == 1 && r.frame % 4 == 0) {  // misses of person 1
      ++dropped;
      continue;
    }
    if (r.id == 2 && r.frame >= 20) r.id = 7;  // one id switch for person 2
    est.push_back(r);
  }
  est.push_back({5, 99, cv::Rect2d(-500, -500, 30, 80), 0.5, {}, {}});  // a false positive
  const MotMetrics m = EvaluateMot(gt, est);
  EXPECT_EQ(m.fn, dropped);
  EXPECT_EQ(m.fp, 1);
  EXPECT_EQ(m.id_switches, 1);
  EXPECT_NEAR(m.mota, 1.0 - double(dropped + 1 + 1) / gt.size(), 1e-12);
  // IDF1: person 2 is split in halves, only one half counts.
  const int half = frames / 2;
  const double idtp = (frames - dropped) + half + frames;
  EXPECT_NEAR(m.idf1, 2 * idtp / (gt.size() + est.size()), 1e-12);
  EXPECT_LT(m.hota, 1.0);
  EXPECT_GT(m.hota, 0.5);
}

TEST(Mot, ShiftedBoxesBelowIouThresholdDoNotMatch) {
  std::vector<TrackRow> gt = {{0, 1, cv::Rect2d(0, 0, 10, 10), 1, {}, {}}};
  std::vector<TrackRow> est = {{0, 1, cv::Rect2d(6, 0, 10, 10), 1, {}, {}}};  // IoU 4/16
  const MotMetrics m = EvaluateMot(gt, est);
  EXPECT_EQ(m.tp, 0);
  EXPECT_EQ(m.fp, 1);
  EXPECT_EQ(m.fn, 1);
}

TEST(Mot, CsvRoundTripAndBadFile) {
  const std::string dir = fv::testing::TempDir();
  std::vector<TrackRow> rows = {{3, 2, cv::Rect2d(1.5, 2.5, 30, 60), 0.75, 1.25, -2.5},
                                {4, 2, cv::Rect2d(2, 3, 30, 60), 0.5, {}, {}}};
  WriteTracksCsv(rows, dir + "/t.csv");
  const auto back = ReadTracksCsv(dir + "/t.csv");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].frame, 3);
  EXPECT_NEAR(back[0].box.x, 1.5, 1e-9);
  ASSERT_TRUE(back[0].x_m.has_value());
  EXPECT_NEAR(*back[0].y_m, -2.5, 1e-9);
  EXPECT_FALSE(back[1].x_m.has_value());
  EXPECT_THROW(ReadTracksCsv(dir + "/missing.csv"), fv::Error);
  {
    // Saved by a spreadsheet ("CSV UTF-8"): a byte-order mark before the header.
    std::ofstream marked(dir + "/marked.csv", std::ios::binary);
    marked << "\xEF\xBB\xBF"
           << "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n"
           << "1,2,3,4,5,6,0.9,1.5,2.5,0.04\n";
  }
  const auto marked = ReadTracksCsv(dir + "/marked.csv");
  ASSERT_EQ(marked.size(), 1u);
  ASSERT_TRUE(marked[0].x_m.has_value());
  EXPECT_NEAR(*marked[0].x_m, 1.5, 1e-12);
  {
    std::ofstream bad(dir + "/bad.csv");
    bad << "frame,id,bb_left,bb_top,bb_width,bb_height\n1,2,abc,4,5,6\n";
  }
  EXPECT_THAT([&] { ReadTracksCsv(dir + "/bad.csv"); },
              ThrowsMessage<fv::Error>(HasSubstr("bad.csv:2")));
  // A row cut short (a write that stopped) is an error, not a row without a field position; so is
  // a MOTChallenge row with fewer columns than the first.
  {
    std::ofstream cut(dir + "/cut.csv");
    cut << "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n"
        << "1,2,3,4,5,6,0.9,1.5,2.5,0.04\n1,3,3,4,5,6,0.9\n";
    std::ofstream mot(dir + "/cut.txt");
    mot << "1,2,3,4,5,6,0.9,-1,-1,-1\n2,2,3,4,5,6,0.9,-1,-1\n";
  }
  EXPECT_THAT([&] { ReadTracksCsv(dir + "/cut.csv"); },
              ThrowsMessage<fv::Error>(HasSubstr("cut.csv:3: 7 fields, the header has 10")));
  EXPECT_THAT([&] { ReadTracksCsv(dir + "/cut.txt"); },
              ThrowsMessage<fv::Error>(HasSubstr("cut.txt:2: 9 fields, the first row has 10")));
}

TEST(Mot, NumbersOutOfRangeNameTheLine) {
  const std::string dir = fv::testing::TempDir();
  const std::string header = "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m,time_s\n";
  for (const std::string row :
       {"1,1,0,0,10,20,1,nan,0,", "1,1,0,0,10,20,1,1e300,0,", "1,1,0,0,10,20,1,0,inf,",
        "1,1,nan,0,10,20,1,,,", "1,1,0,0,1e300,20,1,,,", "1,1,0,0,10,20,nan,,,",
        "1,1,0,0,10,20,1,,,nan"}) {
    SCOPED_TRACE(row);
    std::ofstream(dir + "/r.csv", std::ios::trunc) << header << "1,1,0,0,10,20,1,,,\n" << row;
    EXPECT_THAT([&] { ReadTracksCsv(dir + "/r.csv"); },
                ThrowsMessage<fv::Error>(HasSubstr("r.csv:3")));
  }
}

TEST(Mot, TwoBoxesOfOneIdInAFrameAreRefused) {
  fv::testing::SeededRng rng(5);
  const auto gt = Walkers(rng, 2, 10);
  auto est = gt;
  est.push_back(gt[3]);  // frame 3 of id 1 twice: IDF1 was 1.1
  for (const bool in_est : {true, false}) {
    EXPECT_THAT([&] { in_est ? EvaluateMot(gt, est) : EvaluateMot(est, gt); },
                ThrowsMessage<fv::Error>(
                    ::testing::AllOf(HasSubstr(in_est ? "estimate" : "ground truth"),
                                     HasSubstr("id 1 has two boxes in frame 3 (rows 4 and 21)"))));
  }
}

// TRACKS.csv keeps time_s; a file without it (older TRACKS.csv) still reads.
TEST(Mot, TimeRoundTripAndMotChallengeOutput) {
  const std::string dir = fv::testing::TempDir();
  std::vector<TrackRow> rows = {{1, 2, cv::Rect2d(1, 2, 30, 60), 0.75, 1.0, 2.0, 0.0},
                                {2, 2, cv::Rect2d(2, 3, 30, 60), 0.5, {}, {}, 0.1}};
  WriteTracksCsv(rows, dir + "/t.csv");
  const auto back = ReadTracksCsv(dir + "/t.csv");
  ASSERT_EQ(back.size(), 2u);
  ASSERT_TRUE(back[1].time_s.has_value());
  EXPECT_NEAR(*back[1].time_s, 0.1, 1e-9);
  EXPECT_FALSE(back[1].x_m.has_value());
  {
    std::ofstream old(dir + "/old.csv");
    old << "frame,id,bb_left,bb_top,bb_width,bb_height,conf,x_m,y_m\n1,4,1,2,3,4,0.9,5,6\n";
  }
  const auto o = ReadTracksCsv(dir + "/old.csv");
  ASSERT_EQ(o.size(), 1u);
  EXPECT_FALSE(o[0].time_s.has_value());
  EXPECT_NEAR(*o[0].y_m, 6.0, 1e-12);
  // The MOTChallenge file has no header and ten columns; it reads back as the same boxes.
  WriteMotChallenge(rows, dir + "/mot.txt");
  std::ifstream in(dir + "/mot.txt");
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "1,2,1.00,2.00,30.00,60.00,0.7500,-1,-1,-1");
  const auto mot = ReadTracksCsv(dir + "/mot.txt");
  ASSERT_EQ(mot.size(), 2u);
  EXPECT_EQ(mot[1].frame, 2);
  EXPECT_FALSE(mot[1].x_m.has_value());
}

// MOT17 ground truth (9 columns: conf 0 = ignore, class, visibility) scored as TrackEval does:
// a static person (class 7) matched by the tracker is neither a hit nor a false positive, a car
// (class 3) and a zero-marked pedestrian are not misses.
TEST(Mot, Mot17RulesIgnoreDistractorsAndZeroMarkedRows) {
  const std::string dir = fv::testing::TempDir();
  {
    std::ofstream gt(dir + "/gt.txt");
    for (int f = 1; f <= 10; ++f) {
      gt << f << ",1,100,100,40,100,1,1,1\n";    // pedestrian
      gt << f << ",2,300,100,40,100,1,7,0.8\n";  // static person (distractor)
      gt << f << ",3,500,100,80,60,0,3,1\n";     // car, zero-marked
      gt << f << ",4,700,100,40,100,0,1,0.1\n";  // pedestrian marked 0 (ignore)
    }
  }
  const auto gt = ReadTracksCsv(dir + "/gt.txt");
  ASSERT_EQ(gt.size(), 40u);
  EXPECT_EQ(gt[1].mot_class, 7);
  EXPECT_NEAR(gt[1].visibility, 0.8, 1e-12);
  std::vector<TrackRow> est;
  for (int f = 1; f <= 10; ++f) {
    est.push_back({f, 11, cv::Rect2d(101, 100, 40, 100), 0.9, {}, {}});  // the pedestrian
    est.push_back({f, 12, cv::Rect2d(300, 102, 40, 100), 0.9, {}, {}});  // the static person
  }
  const MotMetrics m = EvaluateMot(gt, est);
  EXPECT_EQ(m.preprocessing.gt_ignored, 30);
  EXPECT_EQ(m.preprocessing.est_on_distractors, 10);
  EXPECT_EQ(m.tp, 10);
  EXPECT_EQ(m.fp, 0);
  EXPECT_EQ(m.fn, 0);
  EXPECT_DOUBLE_EQ(m.mota, 1.0);
  // Without the rules every row counts.
  MotOptions all;
  all.mot17_rules = false;
  const MotMetrics raw = EvaluateMot(gt, est, all);
  EXPECT_EQ(raw.fn, 20);
  EXPECT_LT(raw.mota, 0.6);
}

// An estimate numbered from 0 against 1-based ground truth: the shift is reported, and
// --frame-offset 1 scores it fully; estimated rows beyond the ground truth's frames are left out.
TEST(Mot, FrameAlignment) {
  fv::testing::SeededRng rng(5);
  auto gt = Walkers(rng, 4, 30);
  for (auto& r : gt) r.frame += 1;  // 1..30
  std::vector<TrackRow> est;
  for (auto r : gt) {
    r.frame -= 1;  // 0..29
    est.push_back(r);
  }
  est.push_back({40, 9, cv::Rect2d(0, 0, 30, 80), 0.9, {}, {}});  // beyond the ground truth
  const MotMetrics shifted = EvaluateMot(gt, est);
  EXPECT_EQ(shifted.preprocessing.best_offset, 1);
  EXPECT_NE(shifted.preprocessing.Summary().find("--frame-offset 1"), std::string::npos)
      << shifted.preprocessing.Summary();
  MotOptions o;
  o.frame_offset = 1;
  const MotMetrics fixed = EvaluateMot(gt, est, o);
  EXPECT_DOUBLE_EQ(fixed.mota, 1.0);
  EXPECT_EQ(fixed.preprocessing.best_offset, 0);
  EXPECT_EQ(fixed.preprocessing.est_outside_gt_frames, 1);
  EXPECT_EQ(fixed.preprocessing.Summary().find("WARNING"), std::string::npos);
}

TEST(MotStages, ClearMotKeepsLastFramesPairWhileItOverlaps) {
  const std::vector<TrackRow> gt = {{1, 1, cv::Rect2d(0, 0, 20, 40)}};
  const std::vector<TrackRow> est = {{1, 7, cv::Rect2d(6, 0, 20, 40)},
                                     {1, 8, cv::Rect2d(1, 0, 20, 40)}};
  const MotIndex index = IndexMotRows(gt, est);
  const MotFrame& f = index.frames.at(1);
  const auto iou = FrameIou(f);
  ASSERT_GE(iou[0][0], 0.5);
  EXPECT_GT(iou[0][1], iou[0][0]);
  EXPECT_EQ(MatchClearMot(f, iou, {}, 0.5), (std::vector<int>{1}));        // the better overlap
  EXPECT_EQ(MatchClearMot(f, iou, {{1, 7}}, 0.5), (std::vector<int>{0}));  // kept from last frame
  EXPECT_EQ(MatchClearMot(f, iou, {}, 0.99), (std::vector<int>{-1}));
}

TEST(MotStages, IdentityScoresPairIdsOneToOne) {
  MotMetrics m;
  m.gt_boxes = 10;
  m.est_boxes = 12;
  // gt 0 overlaps est 0 in 5 frames and est 1 in 6; gt 1 only est 1 in 4: 5 + 4 beats 6.
  ScoreIdentity({{5, 6}, {0, 4}}, m);
  EXPECT_DOUBLE_EQ(m.idf1, 2.0 * 9 / 22);
  EXPECT_DOUBLE_EQ(m.idp, 9.0 / 12);
  EXPECT_DOUBLE_EQ(m.idr, 9.0 / 10);
}

}  // namespace
}  // namespace fv::track
