#include "core/colmap_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.h"
#include "test/support/temp_folder.h"

namespace curvesfm {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

class ColmapModelTest : public testing::TempFolderTest {
 protected:
  // A rotation of 90 degrees about z (w = x = 0, z = y = sqrt(1/2)) and a translation.
  void writeText(const std::string& cameras) const {
    write("cameras.txt", "# Camera list\n" + cameras);
    write("images.txt",
          "# Image list with two lines of data per image\n"
          "1 0.70710678118654757 0 0 0.70710678118654757 1 2 3 1 seq/a.png\n"
          "10.5 2.5 -1\n"
          "2 1 0 0 0 0 0 0 1 b.png\n"
          "\n");
  }
};

TEST_F(ColmapModelTest, TextModelGivesCameraAndWorldToCameraPoses) {
  writeText("1 OPENCV 640 480 500 501 320 240 0.1 0.01 0.001 0.002\n");
  const ColmapModel model = readColmapModel(dir_.string());
  ASSERT_EQ(model.cameras.count(1), 1u);
  const Camera& camera = model.cameras.at(1);
  EXPECT_EQ(camera.fy(), 501.0);
  // COLMAP's pixel centres are at +0.5.
  EXPECT_EQ(camera.cx(), 319.5);
  EXPECT_EQ(camera.intrinsics().p2, 0.002);
  EXPECT_EQ(camera.width(), 640);
  ASSERT_EQ(model.images.size(), 2u);
  EXPECT_EQ(model.images[0].name, "seq/a.png");
  EXPECT_EQ(model.images[1].image_id, 2);
  const Pose3& a = model.images[0].cam_from_world;
  EXPECT_NEAR((a * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(1, 3, 3)).norm(), 0.0, 1e-12);
}

TEST_F(ColmapModelTest, SimpleModelsShareOneFocalLength) {
  writeText("1 SIMPLE_RADIAL 64 48 50 32 24 -0.2\n");
  const Camera camera = readColmapModel(dir_.string()).cameras.at(1);
  EXPECT_EQ(camera.fx(), 50.0);
  EXPECT_EQ(camera.fy(), 50.0);
  EXPECT_EQ(camera.intrinsics().k1, -0.2);
}

TEST_F(ColmapModelTest, UnsupportedCameraModelNamesFileAndLine) {
  writeText("1 OPENCV_FISHEYE 64 48 50 50 32 24 0 0 0 0\n");
  EXPECT_THAT([&] { readColmapModel(dir_.string()); },
              ThrowsMessage<ParseError>(AllOf(HasSubstr(path("cameras.txt") + ":2:"),
                                              HasSubstr("found OPENCV_FISHEYE"))));
}

TEST_F(ColmapModelTest, UnknownCameraModelNamesFileAndLine) {
  writeText("1 PINHOLEX 64 48 50 50 32 24\n");
  EXPECT_THAT([&] { readColmapModel(dir_.string()); },
              ThrowsMessage<ParseError>(
                  AllOf(HasSubstr(path("cameras.txt") + ":2:"), HasSubstr("\"PINHOLEX\""))));
}

TEST_F(ColmapModelTest, WrongParameterCountNamesTheModel) {
  writeText("1 PINHOLE 64 48 50 50 32\n");
  EXPECT_THAT([&] { readColmapModel(dir_.string()); },
              ThrowsMessage<ParseError>(AllOf(HasSubstr(path("cameras.txt") + ":2:"),
                                              HasSubstr("4 PINHOLE parameters"))));
}

TEST_F(ColmapModelTest, ImageOfAnUnknownCameraNamesTheLine) {
  writeText("7 PINHOLE 64 48 50 50 32 24\n");
  EXPECT_THAT([&] { readColmapModel(dir_.string()); },
              ThrowsMessage<ParseError>(
                  AllOf(HasSubstr(path("images.txt") + ":2:"), HasSubstr("CAMERA_ID"))));
}

TEST_F(ColmapModelTest, MissingModelListsWhatItLookedFor) {
  EXPECT_THAT([&] { readColmapModel(dir_.string()); },
              ThrowsMessage<IoError>(HasSubstr("cameras.txt + images.txt")));
}

template <class T>
void put(std::ofstream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

TEST_F(ColmapModelTest, BinaryModelReadsLikeText) {
  {
    std::ofstream cameras(path("cameras.bin"), std::ios::binary);
    put<std::uint64_t>(cameras, 1);
    put<std::uint32_t>(cameras, 3);
    put<std::int32_t>(cameras, 1);  // PINHOLE
    put<std::uint64_t>(cameras, 64);
    put<std::uint64_t>(cameras, 48);
    for (double p : {50.0, 51.0, 32.0, 24.0}) put(cameras, p);
    std::ofstream images(path("images.bin"), std::ios::binary);
    put<std::uint64_t>(images, 1);
    put<std::uint32_t>(images, 9);
    for (double v : {1.0, 0.0, 0.0, 0.0, 4.0, 5.0, 6.0}) put(images, v);
    put<std::uint32_t>(images, 3);
    images.write("x.png", 6);
    put<std::uint64_t>(images, 1);
    put(images, 1.0);
    put(images, 2.0);
    put<std::int64_t>(images, -1);
  }
  const ColmapModel model = readColmapModel(dir_.string());
  EXPECT_EQ(model.cameras.at(3).cy(), 23.5);
  ASSERT_EQ(model.images.size(), 1u);
  EXPECT_EQ(model.images[0].name, "x.png");
  EXPECT_EQ(model.images[0].cam_from_world.translation().z(), 6.0);
}

TEST_F(ColmapModelTest, TruncatedBinaryNamesTheByte) {
  {
    std::ofstream cameras(path("cameras.bin"), std::ios::binary);
    put<std::uint64_t>(cameras, 2);
    put<std::uint32_t>(cameras, 3);
  }
  write("images.bin", "");
  EXPECT_THAT([&] { readColmapModel(dir_.string()); },
              ThrowsMessage<ParseError>(AllOf(HasSubstr(path("cameras.bin")),
                                              HasSubstr("model_id at byte 12"),
                                              HasSubstr("end of the file (12 bytes)"))));
}

TEST_F(ColmapModelTest, PosesForASequenceMatchByNameThenFileName) {
  writeText("1 PINHOLE 64 48 50 50 32 24\n");
  ImageSequence sequence;
  sequence.dir = "seq";
  sequence.images = {
      {0.0, "/d/a.png", "a.png"}, {1.0, "/d/c.png", "c.png"}, {2.0, "/d/b.png", "b.png"}};
  const std::vector<StampedPose> poses =
      colmapPosesForSequence(readColmapModel(dir_.string()), sequence);
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].timestamp, 0.0);
  EXPECT_EQ(poses[1].timestamp, 2.0);
  // Camera-to-world: the first camera's centre is -R^T t.
  EXPECT_NEAR((poses[0].world_from_cam.translation() - Eigen::Vector3d(-2, 1, -3)).norm(), 0.0,
              1e-12);
  sequence.images = {{0.0, "/d/z.png", "z.png"}};
  EXPECT_THAT([&] { colmapPosesForSequence(readColmapModel(dir_.string()), sequence); },
              ThrowsMessage<ParseError>(AllOf(HasSubstr(dir_.string()), HasSubstr("z.png"))));
}

TEST_F(ColmapModelTest, TheCameraOfAOneCameraModelIsASequencesCamera) {
  writeText("1 PINHOLE 64 48 50 51 32 24\n");
  const std::optional<FallbackCamera> camera = colmapModelCamera(dir_.string());
  ASSERT_TRUE(camera.has_value());
  EXPECT_EQ(camera->camera.fy(), 51.0);
  EXPECT_EQ(camera->camera.cx(), 31.5);
  EXPECT_THAT(camera->source, HasSubstr(dir_.string()));
  writeText("1 PINHOLE 64 48 50 51 32 24\n2 PINHOLE 64 48 60 61 32 24\n");
  EXPECT_FALSE(colmapModelCamera(dir_.string()).has_value());
}

}  // namespace
}  // namespace curvesfm
