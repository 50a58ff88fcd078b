#include "fieldvision/dnn/nanodet.h"

#include <array>
#include <fstream>

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"
#include "fieldvision/util/testing.h"

namespace fv::dnn {
namespace {

// NanoDet outputs of a w x h input with hot cells: (stride, col, row, class, score) with the given
// side distances (in strides) as one-hot bins.
struct Hot {
  int stride, col, row, class_id;
  float score;
  int sides[4];
};
std::vector<cv::Mat> FakeOutputs(int w, int h, const std::vector<Hot>& hot) {
  std::vector<cv::Mat> outs;
  for (int k : {80, 44}) {
    for (int s : {8, 16, 32}) {
      const int n = ((w + s - 1) / s) * ((h + s - 1) / s);
      int sz[] = {1, n, k};
      outs.emplace_back(3, sz, CV_32F, cv::Scalar(k == 80 ? 0.01 : 0.0));
    }
  }
  for (const Hot& c : hot) {
    const int level = c.stride == 8 ? 0 : (c.stride == 16 ? 1 : 2);
    const int idx = c.row * ((w + c.stride - 1) / c.stride) + c.col;
    outs[level].ptr<float>()[idx * 80 + c.class_id] = c.score;
    for (int k = 0; k < 4; ++k) outs[3 + level].ptr<float>()[idx * 44 + k * 11 + c.sides[k]] = 40;
  }
  return outs;
}

TEST(DecodeNanoDet, RecoversBoxesOfTheAskedClassesAtEveryStride) {
  fv::testing::SeededRng rng(12);
  const int w = 416, h = 320;
  for (int trial = 0; trial < 20; ++trial) {
    const int stride = std::array<int, 3>{8, 16, 32}[rng.UniformInt(0, 2)];
    Hot ball{stride,
             rng.UniformInt(3, w / stride - 4),
             rng.UniformInt(3, h / stride - 4),
             kCocoSportsBall,
             0.7f,
             {}};
    for (int& s : ball.sides) s = rng.UniformInt(1, 3);
    const Hot person{16, 2, 2, kCocoPerson, 0.9f, {1, 1, 2, 2}};
    const auto outs = FakeOutputs(w, h, {ball, person});
    const auto balls = DecodeNanoDet(outs, w, h, 0.5, {kCocoSportsBall});
    ASSERT_EQ(balls.size(), 1u);
    EXPECT_EQ(balls[0].class_id, kCocoSportsBall);
    const double cx = (ball.col + 0.5) * stride, cy = (ball.row + 0.5) * stride;
    EXPECT_NEAR(balls[0].box.x, cx - stride * ball.sides[0], 1e-3);
    EXPECT_NEAR(balls[0].box.y, cy - stride * ball.sides[1], 1e-3);
    EXPECT_NEAR(balls[0].box.br().x, cx + stride * ball.sides[2], 1e-3);
    EXPECT_NEAR(balls[0].box.br().y, cy + stride * ball.sides[3], 1e-3);
    EXPECT_NEAR(balls[0].score, 0.7, 1e-6);
    const auto both = DecodeNanoDet(outs, w, h, 0.5, {kCocoPerson, kCocoSportsBall});
    EXPECT_EQ(both.size(), 2u);
    EXPECT_TRUE(DecodeNanoDet(outs, w, h, 0.8, {kCocoSportsBall}).empty());
  }
}

TEST(DecodeNanoDet, RejectsBadClassesAndSizes) {
  const auto outs = FakeOutputs(64, 64, {});
  EXPECT_NE(fv::testing::ErrorOf([&] { DecodeNanoDet(outs, 64, 64, 0.5, {80}); }).find("80"),
            std::string::npos);
  EXPECT_NE(fv::testing::ErrorOf([&] { DecodeNanoDet(outs, 96, 64, 0.5, {0}); }).find("96x64"),
            std::string::npos);
}

TEST(NmsBoxes, SuppressesWithinAClassOnly) {
  const std::vector<DnnBox> in = {{cv::Rect2d(10, 10, 20, 20), 0.6, kCocoSportsBall},
                                  {cv::Rect2d(11, 10, 20, 20), 0.8, kCocoSportsBall},
                                  {cv::Rect2d(10, 10, 20, 20), 0.7, kCocoPerson},
                                  {cv::Rect2d(100, 10, 20, 20), 0.3, kCocoSportsBall}};
  const auto out = NmsBoxes(in, 0.5);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_DOUBLE_EQ(out[0].score, 0.8);
  EXPECT_EQ(out[1].class_id, kCocoPerson);
  EXPECT_DOUBLE_EQ(out[2].score, 0.3);
}

// The shipped model's errors say how to get it again (`make build`); a user's own model's name
// the file only (make build would not mend it).
TEST(NanoDet, MissingOrCorruptModelSaysHowToGetIt) {
  const std::string missing = fv::testing::TempDir() + "/none.onnx";
  const std::string own = fv::testing::ErrorOf([&] { NanoDet net(missing); });
  EXPECT_NE(own.find(missing), std::string::npos) << own;
  EXPECT_EQ(own.find("make build"), std::string::npos) << own;
  EXPECT_NE(fv::testing::ErrorOf([&] { LoadOnnx(missing, /*shipped=*/true); }).find("make build"),
            std::string::npos);
  const std::string corrupt = fv::testing::TempDir() + "/corrupt.onnx";
  std::ofstream(corrupt) << "not a model";
  const std::string e = fv::testing::ErrorOf([&] { NanoDet net(corrupt); });
  EXPECT_NE(e.find("corrupt.onnx"), std::string::npos) << e;
  EXPECT_EQ(e.find("make build"), std::string::npos) << e;
  const std::string none = fv::testing::ErrorOf([] { FindModel("no-such-model.onnx"); });
  EXPECT_NE(none.find("no-such-model.onnx"), std::string::npos) << none;
  EXPECT_NE(none.find("fetch-models.sh"), std::string::npos) << none;
}

}  // namespace
}  // namespace fv::dnn
