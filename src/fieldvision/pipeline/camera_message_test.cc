#include "fieldvision/pipeline/camera_message.h"

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/seeded_rng.h"

namespace fv::pipeline {
namespace {

TEST(CameraMessage, JsonLineRoundTripsExactly) {
  testing::SeededRng rng(21);
  for (int trial = 0; trial < 20; ++trial) {
    CameraMessage m;
    m.camera = rng.UniformInt(0, 7);
    m.frame = rng.UniformInt(0, 100000);
    m.time_s = rng.Uniform(0, 1000);
    for (int k = rng.UniformInt(0, 4); k > 0; --k) {
      recon::BallObservation o;
      o.centre_px = {rng.Uniform(-10, 2000), rng.Uniform(-10, 2000)};
      o.radius_px = rng.Uniform(0, 50);
      o.sigma_px = rng.Uniform(0.01, 3);
      o.score = rng.Uniform(0, 1);
      o.weak = rng.UniformInt(0, 1) == 1;
      if (rng.UniformInt(0, 1) == 1) o.background_change = rng.Uniform(0, 1);
      m.candidates.push_back(o);
    }
    const std::string line = m.ToJsonLine();
    EXPECT_EQ(line.find('\n'), std::string::npos);
    const CameraMessage back = CameraMessage::FromJsonLine(line);
    EXPECT_EQ(back.camera, m.camera);
    EXPECT_EQ(back.frame, m.frame);
    EXPECT_EQ(back.time_s, m.time_s);
    ASSERT_EQ(back.candidates.size(), m.candidates.size());
    for (size_t k = 0; k < m.candidates.size(); ++k) {
      EXPECT_EQ(back.candidates[k].centre_px, m.candidates[k].centre_px);
      EXPECT_EQ(back.candidates[k].radius_px, m.candidates[k].radius_px);
      EXPECT_EQ(back.candidates[k].sigma_px, m.candidates[k].sigma_px);
      EXPECT_EQ(back.candidates[k].score, m.candidates[k].score);
      EXPECT_EQ(back.candidates[k].weak, m.candidates[k].weak);
      EXPECT_EQ(back.candidates[k].background_change, m.candidates[k].background_change);
    }
  }
}

TEST(CameraMessage, BadLinesNameTheProblem) {
  auto message_of = [](const std::string& line) {
    try {
      CameraMessage::FromJsonLine(line, "cam1.jsonl:3");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message_of("{not json").find("cam1.jsonl:3"), std::string::npos);
  EXPECT_NE(message_of(R"({"frame":1,"time_s":0,"candidates":[]})").find("'camera'"),
            std::string::npos);
  EXPECT_NE(message_of(R"({"camera":0,"frame":1,"time_s":"x","candidates":[]})").find("time_s"),
            std::string::npos);
  EXPECT_NE(message_of(
                R"({"camera":0,"frame":1,"time_s":0,"candidates":[{"u":1,"v":2,"r":1,"score":1}]})")
                .find("sigma"),
            std::string::npos);
  EXPECT_NE(
      message_of(
          R"({"camera":0,"frame":1,"time_s":0,"candidates":[{"u":1,"v":2,"r":1,"sigma":1,"score":1,"weak":1}]})")
          .find("'weak'"),
      std::string::npos);
  EXPECT_NE(
      message_of(
          R"({"camera":0,"frame":1,"time_s":0,"candidates":[{"u":1,"v":2,"r":1,"sigma":1,"score":1,"bg":1.5}]})")
          .find("'bg' must be in [0, 1]"),
      std::string::npos);
}

}  // namespace
}  // namespace fv::pipeline
