#include "fieldvision/detect/colour.h"

#include <filesystem>
#include <fstream>
#include <functional>

#include <gtest/gtest.h>

#include "fieldvision/util/error.h"
#include "fieldvision/util/random.h"
#include "fieldvision/util/testing.h"

namespace fv::detect {
namespace {

std::string WriteText(const std::string& name, const std::string& text) {
  std::string path = fv::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ColourTable, PresetSpecSeparatesBallGrassAndLines) {
  const ColourTable t(PresetColourSpec("orange"));
  const uint8_t ball = t.ClassBit("ball"), field = t.ClassBit("field"), line = t.ClassBit("line");
  EXPECT_EQ(t.Classify(0, 110, 255), ball);        // the synthetic ball
  EXPECT_EQ(t.Classify(0, 45, 100), ball);         // its shaded side
  EXPECT_EQ(t.Classify(50, 140, 60), field);       // grass
  EXPECT_EQ(t.Classify(235, 235, 235), line);      // paint
  EXPECT_EQ(t.Classify(140, 170, 215) & ball, 0);  // skin
  EXPECT_EQ(t.Classify(40, 40, 200) & ball, 0);    // red shirt
  EXPECT_EQ(t.Classify(35, 35, 35), 0);            // robot
}

TEST(ColourTable, TableAgreesWithTheRangesForRandomColours) {
  const uint64_t seed = fv::testing::TestSeed(7);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  ColourSpec spec = PresetColourSpec("orange");
  spec.classes.push_back(ColourPreset("red"));  // wraps through hue 0
  spec.classes.push_back({"yuv", {{ColourSpace::kYuv, {50, 90, 140}, {220, 130, 255}}}});
  const ColourTable t(spec);
  for (int i = 0; i < 20000; ++i) {
    const uint8_t b = rng.UniformInt(0, 255), g = rng.UniformInt(0, 255),
                  r = rng.UniformInt(0, 255);
    ASSERT_EQ(t.Classify(b, g, r), ClassifyBySpec(spec, b, g, r))
        << int(b) << "," << int(g) << "," << int(r);
  }
  EXPECT_NE(t.Classify(0, 0, 255) & t.ClassBit("red"), 0);
}

// The widened ball class joins the spec as one more class: the spec's own classes keep their
// bits, the new one classifies as WidenedBallSpec's; a full spec (8 classes) stays as it is.
TEST(ColourSpec, WidenedBallIsOneMoreClassWhenThereIsRoom) {
  const uint64_t seed = fv::testing::TestSeed(11);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourSpec spec = PresetColourSpec("yellow");
  const ColourSpec with = WithWidenedBall(spec, 10.0, 0.6);
  ASSERT_EQ(with.classes.size(), spec.classes.size() + 1);
  EXPECT_EQ(with.classes.back().name, WidenedBallClass(spec));
  EXPECT_EQ(with.ball_class, spec.ball_class);
  const ColourSpec wide = WidenedBallSpec(spec, 10.0, 0.6);
  const uint8_t own = uint8_t((1u << spec.classes.size()) - 1);
  const uint8_t wide_bit = uint8_t(1u << spec.classes.size());
  const uint8_t ball_bit = uint8_t(1u << spec.Find(spec.ball_class));
  int widened_only = 0;
  for (int i = 0; i < 20000; ++i) {
    const uint8_t b = rng.UniformInt(0, 255), g = rng.UniformInt(0, 255),
                  r = rng.UniformInt(0, 255);
    const uint8_t bits = ClassifyBySpec(with, b, g, r);
    ASSERT_EQ(bits & own, ClassifyBySpec(spec, b, g, r));
    ASSERT_EQ((bits & wide_bit) != 0, ClassifyBySpec(wide, b, g, r) != 0);
    widened_only += (bits & wide_bit) != 0 && (bits & ball_bit) == 0;
  }
  EXPECT_GT(widened_only, 0);  // the widened class is wider
  ColourSpec full = spec;
  while (full.classes.size() < 8) {
    full.classes.push_back({"c" + std::to_string(full.classes.size()), spec.classes[0].ranges});
  }
  EXPECT_EQ(WithWidenedBall(full).classes.size(), 8u);
}

TEST(ColourTable, QuantisedTableMatchesTheExactTableAtCellCentres) {
  const uint64_t seed = fv::testing::TestSeed(3);
  FV_SEED_TRACE(seed);
  util::Rng rng(seed);
  const ColourSpec spec = PresetColourSpec("orange");
  const ColourTable exact(spec, 8), q6(spec, 6);
  int agree = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const uint8_t b = rng.UniformInt(0, 63) * 4 + 2, g = rng.UniformInt(0, 63) * 4 + 2,
                  r = rng.UniformInt(0, 63) * 4 + 2;
    ASSERT_EQ(q6.Classify(b, g, r), exact.Classify(b, g, r));
    const uint8_t b2 = rng.UniformInt(0, 255), g2 = rng.UniformInt(0, 255),
                  r2 = rng.UniformInt(0, 255);
    agree += q6.Classify(b2, g2, r2) == exact.Classify(b2, g2, r2);
  }
  EXPECT_GT(agree, 0.95 * n);
}

TEST(ColourSpec, JsonRoundTripAndSharedTables) {
  ColourSpec spec = PresetColourSpec("pink");
  spec.classes[0].ranges.push_back({ColourSpace::kYuv, {10, 20, 30}, {200, 210, 220}});
  const std::string path = fv::testing::TempDir() + "/pink.json";
  WriteColourSpec(spec, path);
  const ColourSpec back = ReadColourSpec(path);
  EXPECT_EQ(ColourSpecToJson(back), ColourSpecToJson(spec));
  EXPECT_EQ(LoadColourSpec(path).classes.size(), spec.classes.size());
  EXPECT_EQ(ColourTable::Shared(spec).get(), ColourTable::Shared(back).get());
}

TEST(ColourSpec, BadFilesGiveOneLineErrorsNamingTheFile) {
  const std::string empty = WriteText("empty.json", "  \n");
  EXPECT_NE(ErrorOf([&] { LoadColourSpec(empty); }).find("empty.json' is empty"),
            std::string::npos);
  const std::string bad = WriteText("bad.json", "{\"classes\": [ {\"name\": ");
  const std::string e1 = ErrorOf([&] { LoadColourSpec(bad); });
  EXPECT_NE(e1.find("bad.json' is not valid JSON"), std::string::npos) << e1;
  EXPECT_EQ(e1.find('\n'), std::string::npos);
  const std::string inverted = WriteText(
      "inv.json", R"({"classes":[{"name":"ball","ranges":[{"space":"hsv","min":[0,200,0],)"
                  R"("max":[30,100,255]}]}]})");
  EXPECT_NE(ErrorOf([&] { LoadColourSpec(inverted); }).find("min > max"), std::string::npos);
  const std::string noball = WriteText(
      "noball.json", R"({"ball_class":"x","classes":[{"name":"ball","ranges":[{"min":[0,0,0],)"
                     R"("max":[30,255,255]}]}]})");
  EXPECT_NE(ErrorOf([&] { LoadColourSpec(noball); }).find("ball_class 'x'"), std::string::npos);
  EXPECT_NE(ErrorOf([] { LoadColourSpec("no-such-colour"); }).find("neither a preset"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { ColourPreset("purple"); }).find("orange"), std::string::npos);
}

}  // namespace
}  // namespace fv::detect
