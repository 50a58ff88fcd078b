#include "fieldvision/track/pets.h"

#include <filesystem>
#include <set>

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fieldvision/camera/camera_io.h"
#include "fieldvision/track/bytetrack.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/testing.h"

namespace fv::track {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

std::string PetsDir() {
  const std::string d = fv::testing::SharedDataDir();
  return d.empty() ? d : d + "/pets2009-s2l1";
}

TEST(Tsai, ConvertedCameraReproducesTsaiProjection) {
  if (PetsDir().empty()) GTEST_SKIP() << "shared data absent";
  const TsaiParameters p = ReadTsaiXml(PetsDir() + "/View_001.xml");
  EXPECT_EQ(p.width, 768);
  EXPECT_EQ(p.height, 576);
  const TsaiConversion c = CameraFromTsai(p, "View_001");
  EXPECT_LT(c.max_fit_error_px, 0.05) << c.Summary();
  // The camera is above the ground and about 20-60 m from the scene.
  const Eigen::Vector3d centre = c.camera.CentreInWorld();
  EXPECT_GT(centre.z(), 3.0) << c.Summary();
  // Round trip through the YAML file.
  const std::string path = fv::testing::TempDir() + "/cam.yaml";
  camera::WriteCameraYaml(c.camera, path);
  const camera::Camera back = camera::ReadCameraYaml(path);
  const Eigen::Vector3d world(5.0, 10.0, 0.0);
  const auto a = back.Project(world);
  ASSERT_TRUE(a.has_value());
  EXPECT_LT((*a - TsaiProject(p, world)).norm(), 0.05);
}

TEST(Pets, AnnotationsImportAndFeetLieOnAPlausibleGround) {
  if (PetsDir().empty()) GTEST_SKIP() << "shared data absent";
  const auto rows = ReadPetsCvml(PetsDir() + "/PETS2009-S2L1.xml");
  std::set<int> frames, ids;
  for (const auto& r : rows) {
    frames.insert(r.frame);
    ids.insert(r.id);
  }
  EXPECT_EQ(*frames.begin(), 1);  // MOTChallenge numbering: CVML frames 0..794
  EXPECT_EQ(*frames.rbegin(), 795);
  EXPECT_GE(ids.size(), 15u);
  EXPECT_GT(rows.size(), 4000u);
  // CVML frame 0 (MOT frame 1), object 15: xc 274.4912 yc 262.9999 w 32.9129 h 88.7021 (first lines
  // of the file).
  bool found = false;
  for (const auto& r : rows) {
    if (r.frame == 1 && r.id == 15) {
      found = true;
      EXPECT_NEAR(r.box.x + 0.5 * r.box.width, 274.4912, 1e-3);
      EXPECT_NEAR(r.box.height, 88.7021, 1e-3);
    }
  }
  EXPECT_TRUE(found);
  // Feet of all annotated people map to the ground within a scene some tens of metres across.
  const camera::Camera cam = CameraFromTsai(ReadTsaiXml(PetsDir() + "/View_001.xml")).camera;
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  int on_ground = 0;
  for (const auto& r : rows) {
    if (r.box.y + r.box.height > 575) continue;  // feet outside the image
    const auto g = FootOnGround(cam, r.box);
    if (!g) continue;
    ++on_ground;
    lo = lo.cwiseMin(*g);
    hi = hi.cwiseMax(*g);
  }
  EXPECT_GT(on_ground, int(rows.size() * 0.9));
  const Eigen::Vector2d extent = hi - lo;
  EXPECT_GT(extent.minCoeff(), 5.0) << lo.transpose() << " .. " << hi.transpose();
  EXPECT_LT(extent.maxCoeff(), 80.0) << lo.transpose() << " .. " << hi.transpose();
}

TEST(Pets, BadFilesGiveErrorsNamingThem) {
  const std::string dir = fv::testing::TempDir();
  EXPECT_THROW(ReadPetsCvml(dir + "/none.xml"), fv::Error);
  EXPECT_THROW(ReadTsaiXml(dir + "/none.xml"), fv::Error);
  {
    std::ofstream f(dir + "/bad.xml");
    f << "<Camera><Geometry width=\"768\"/></Camera>";
  }
  EXPECT_THAT([&] { ReadTsaiXml(dir + "/bad.xml"); },
              ThrowsMessage<fv::Error>(HasSubstr("bad.xml")));
  // An id given twice in a frame (or a frame number twice) is named, not written as ground truth
  // that eval tracks then refuses.
  std::ofstream(dir + "/twice.xml")
      << "<dataset><frame number=\"0\"><objectlist>"
         "<object id=\"9\"><box xc=\"10\" yc=\"10\" w=\"4\" h=\"8\"/></object>"
         "<object id=\"9\"><box xc=\"30\" yc=\"10\" w=\"4\" h=\"8\"/></object>"
         "</objectlist></frame></dataset>";
  EXPECT_THAT([&] { ReadPetsCvml(dir + "/twice.xml"); },
              ThrowsMessage<fv::Error>(HasSubstr("object 9 has a second box in frame 0")));
}

}  // namespace
}  // namespace fv::track
