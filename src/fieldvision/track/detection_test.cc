#include "fieldvision/track/detection.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

// NanoDet outputs with one person cell: stride 16 cell (col, row) with the given side distances
// (in strides) as one-hot bins.
std::vector<cv::Mat> FakeOutputs(int w, int h, int col, int row, const int sides[4], float score) {
  std::vector<cv::Mat> outs;
  for (int s : {8, 16, 32}) {
    const int n = ((w + s - 1) / s) * ((h + s - 1) / s);
    int sz[] = {1, n, 80};
    outs.emplace_back(3, sz, CV_32F, cv::Scalar(0.01));
  }
  for (int s : {8, 16, 32}) {
    const int n = ((w + s - 1) / s) * ((h + s - 1) / s);
    int sz[] = {1, n, 44};
    outs.emplace_back(3, sz, CV_32F, cv::Scalar(0.0));
  }
  const int fw = (w + 15) / 16;
  const int idx = row * fw + col;
  outs[1].ptr<float>()[static_cast<ptrdiff_t>(idx) * 80] = score;
  for (int k = 0; k < 4; ++k) {
    outs[4].ptr<float>()[static_cast<ptrdiff_t>(idx * 44 + k * 11 + sides[k])] = 40.0f;
  }
  return outs;
}

TEST(NanoDetDecode, RecoversTheBoxOfAOneHotDistribution) {
  fv::testing::SeededRng rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const int w = 416, h = 320;
    const int col = rng.UniformInt(4, 20), row = rng.UniformInt(4, 14);
    const int sides[4] = {rng.UniformInt(1, 3), rng.UniformInt(1, 3), rng.UniformInt(1, 3),
                          rng.UniformInt(1, 3)};
    const auto dets = DecodeNanoDet(FakeOutputs(w, h, col, row, sides, 0.8f), w, h, 0.5);
    ASSERT_EQ(dets.size(), 1u);
    const double cx = (col + 0.5) * 16, cy = (row + 0.5) * 16;
    EXPECT_NEAR(dets[0].box.x, cx - 16 * sides[0], 1e-3);
    EXPECT_NEAR(dets[0].box.y, cy - 16 * sides[1], 1e-3);
    EXPECT_NEAR(dets[0].box.x + dets[0].box.width, cx + 16 * sides[2], 1e-3);
    EXPECT_NEAR(dets[0].box.y + dets[0].box.height, cy + 16 * sides[3], 1e-3);
    EXPECT_NEAR(dets[0].score, 0.8, 1e-6);
  }
}

TEST(DetectionsFile, RoundTripsExactlyAndFilteringIsIdempotent) {
  fv::testing::SeededRng rng(5);
  DetectionsFile in;
  in.frames.resize(6);
  for (int f = 0; f < 6; ++f) {
    if (f == 2) continue;  // a frame without detections
    for (int k = 0; k < 4; ++k) {
      in.frames[f].push_back({cv::Rect2d(rng.Uniform(0, 600), rng.Uniform(0, 400),
                                         rng.Uniform(5, 60), rng.Uniform(20, 150)),
                              rng.Uniform(0.1, 1.0)});
    }
  }
  const std::string path = fv::testing::TempDir() + "/det.txt";
  WriteDetectionsCsv(in, path);
  const DetectionsFile out = ReadDetectionsCsv(path);
  ASSERT_EQ(out.frames.size(), in.frames.size());
  for (size_t f = 0; f < in.frames.size(); ++f) {
    ASSERT_EQ(out.frames[f].size(), in.frames[f].size());
    for (size_t k = 0; k < in.frames[f].size(); ++k) {
      EXPECT_EQ(out.frames[f][k].box, in.frames[f][k].box);
      EXPECT_EQ(out.frames[f][k].score, in.frames[f][k].score);
    }
  }
  DetectorOptions o;
  o.min_height_px = 40;
  const FootFilter left_half = [](const cv::Point2d& p) { return p.x < 320; };
  for (const auto& dets : in.frames) {
    const auto once = FilterDetections(dets, o, left_half);
    const auto twice = FilterDetections(once, o, left_half);
    ASSERT_EQ(once.size(), twice.size());
    for (size_t k = 0; k < once.size(); ++k) EXPECT_EQ(once[k].box, twice[k].box);
    for (const auto& d : once) {
      EXPECT_GE(d.box.height, 40);
      EXPECT_LT(d.box.x + 0.5 * d.box.width, 320);
    }
  }
}

TEST(DetectionsFile, MotChallengeColumnsReadAndBadRowsNameFileAndLine) {
  const std::string dir = fv::testing::TempDir();
  {
    std::ofstream f(dir + "/mot.txt");
    f << "1,-1,10,20,30,80,0.9,-1,-1,-1\n\n3,-1,11.5,21,30,81,0.4,-1,-1,-1\n";
  }
  const DetectionsFile d = ReadDetectionsCsv(dir + "/mot.txt");
  ASSERT_EQ(d.frames.size(), 3u);
  EXPECT_EQ(d.frames[0].size(), 1u);
  EXPECT_TRUE(d.frames[1].empty());
  ASSERT_EQ(d.frames[2].size(), 1u);
  EXPECT_DOUBLE_EQ(d.frames[2][0].box.x, 11.5);
  EXPECT_DOUBLE_EQ(d.frames[2][0].score, 0.4);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"1,-1,10,20,30,80\n", "7 columns"},
      {"1,-1,10,20,30,80,0.5\n2,-1,10,x,30,80,0.5\n", "bb_top"},
      {"0,-1,10,20,30,80,0.5\n", "frames count from 1"},
      {"1,-1,10,20,-30,80,0.5\n", "non-negative"},
      {"1,-1,10,20,30,80,0.5\n2,-1,10,20,30,80\n", "6 fields, the first row has 7"},
  };
  for (size_t i = 0; i < bad.size(); ++i) {
    const std::string path = dir + "/bad" + std::to_string(i) + ".txt";
    {
      std::ofstream f(path);
      f << bad[i].first;
    }
    try {
      ReadDetectionsCsv(path);
      ADD_FAILURE() << "no error for " << bad[i].first;
    } catch (const fv::Error& e) {
      const std::string what = e.what();
      const std::string line = i == 1 || i == 4 ? ":2" : ":1";
      EXPECT_NE(what.find(path + line), std::string::npos) << what;
      EXPECT_NE(what.find(bad[i].second), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  EXPECT_THROW(ReadDetectionsCsv(dir + "/missing.txt"), fv::Error);
}

TEST(Nms, KeepsTheBestOfOverlappingBoxes) {
  const std::vector<Detection> d = {{cv::Rect2d(0, 0, 10, 20), 0.6},
                                    {cv::Rect2d(1, 1, 10, 20), 0.9},
                                    {cv::Rect2d(50, 0, 10, 20), 0.4}};
  const auto out = Nms(d, 0.5);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_DOUBLE_EQ(out[0].score, 0.9);
  EXPECT_DOUBLE_EQ(out[1].score, 0.4);
}

TEST(Detector, BadOptionsAndModelsGiveClearErrors) {
  DetectorOptions o;
  o.kind = "yolo9000";
  EXPECT_THROW(o.Check(), fv::Error);
  o = {};
  o.input_width = 100;
  EXPECT_THROW(o.Check(), fv::Error);
  const std::string dir = fv::testing::TempDir();
  o = {};
  o.model_path = dir + "/missing.onnx";
  // A model of the user's own: named, no `make build` advice (that fetches the shipped one).
  const std::string missing = fv::testing::ErrorOf([&] { MakeDetector(o); });
  EXPECT_NE(missing.find(o.model_path), std::string::npos) << missing;
  EXPECT_EQ(missing.find("make build"), std::string::npos) << missing;
  {
    std::ofstream f(dir + "/corrupt.onnx", std::ios::binary);
    f << "this is not a protobuf";
  }
  o.model_path = dir + "/corrupt.onnx";
  const std::string corrupt = fv::testing::ErrorOf([&] { MakeDetector(o); });
  EXPECT_NE(corrupt.find("corrupt.onnx"), std::string::npos) << corrupt;
  EXPECT_EQ(corrupt.find("make build"), std::string::npos) << corrupt;
}

// The converted pretrained model (made by `make build`) finds the person in darknet's sample
// photo at about the score NanoDet gives it (0.74 at 416 x 416), and also with the frame's aspect
// ratio kept (the default).
TEST(NanoDet, FindsThePersonInDarknetsSample) {
  const std::string photo = "/usr/share/darknet/data/person.jpg";
  if (!std::filesystem::exists(photo)) GTEST_SKIP() << "darknet package not installed";
  std::string model;
  try {
    model = FindModel("nanodet.onnx");
  } catch (const fv::Error& e) {
    FAIL() << "the NanoDet model was not set up: " << e.what();
  }
  const cv::Mat img = cv::imread(photo);
  ASSERT_FALSE(img.empty());
  DetectorOptions o;
  o.score_threshold = 0.3;
  o.input_height = 416;
  const auto square = MakeDetector(o)->Detect(img);
  ASSERT_FALSE(square.empty());
  EXPECT_NEAR(square[0].score, 0.74, 0.05);
  o.input_height = 0;
  const auto dets = MakeDetector(o)->Detect(img);
  ASSERT_FALSE(dets.empty());
  // The person stands in the middle of the photo and is most of its height.
  const Detection& best = dets[0];
  EXPECT_GT(best.score, 0.4);
  EXPECT_LT(best.score, 0.95);
  EXPECT_LT(Iou(best.box, square[0].box), 1.01);
  EXPECT_GT(Iou(best.box, square[0].box), 0.7);
  const double cx = best.box.x + 0.5 * best.box.width;
  EXPECT_GT(cx, img.cols * 0.25);
  EXPECT_LT(cx, img.cols * 0.75);
  EXPECT_GT(best.box.height, img.rows * 0.5);
}

}  // namespace
}  // namespace fv::track
