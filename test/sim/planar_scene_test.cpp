#include "sim/planar_scene.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "core/dataset_io.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// A smooth colour texture (a few levels per pixel at most), so that bilinear sampling is exact
// to well under one level and a mismatch means wrong geometry.
cv::Mat smoothTexture(int cols, int rows) {
  cv::Mat texture(rows, cols, CV_8UC3);
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      texture.at<cv::Vec3b>(v, u) =
          cv::Vec3b(cv::saturate_cast<uchar>(128 + 100 * std::sin(u / 17.0)),
                    cv::saturate_cast<uchar>(128 + 100 * std::cos(v / 13.0)),
                    cv::saturate_cast<uchar>(20 + (u + 2 * v) * 200.0 / (cols + 2 * rows)));
    }
  }
  return texture;
}

cv::Vec3d bilinear(const cv::Mat& image, const Eigen::Vector2d& at) {
  const int u = static_cast<int>(std::floor(at.x()));
  const int v = static_cast<int>(std::floor(at.y()));
  const double a = at.x() - u;
  const double b = at.y() - v;
  const auto pixel = [&](int du, int dv) { return cv::Vec3d(image.at<cv::Vec3b>(v + dv, u + du)); };
  return (1 - a) * (1 - b) * pixel(0, 0) + a * (1 - b) * pixel(1, 0) + (1 - a) * b * pixel(0, 1) +
         a * b * pixel(1, 1);
}

// Where the ray through `pixel` meets the plane z = 0, computed without any homography.
Eigen::Vector3d planePointSeenAt(const Camera& camera, const Pose3& cam_from_world,
                                 const Eigen::Vector2d& pixel) {
  const Pose3 world_from_cam = cam_from_world.inverse();
  const Eigen::Vector3d centre = world_from_cam.translation();
  const Eigen::Vector3d ray = world_from_cam.rotationMatrix() * camera.unproject(pixel, 1.0);
  return centre - centre.z() / ray.z() * ray;
}

Eigen::Vector2d textureCoordinates(const PlanarTexture& texture, const Eigen::Vector3d& point) {
  return (texture.planeFromTexture().inverse() * Eigen::Vector3d(point.x(), point.y(), 1.0))
      .hnormalized();
}

PlanarSceneOptions smallOptions() {
  PlanarSceneOptions options;
  options.num_frames = 3;
  options.width = 160;
  options.height = 120;
  options.fx = options.fy = 131.25;  // the default field of view
  options.cx = 79.5;
  options.cy = 59.5;
  return options;
}

std::string validationMessage(const PlanarSceneOptions& options) {
  try {
    options.validate();
  } catch (const InvalidOptions& e) {
    return e.what();
  }
  return "valid";
}

TEST(PlanarSceneOptions, RejectionNamesFieldValueAndConstraint) {
  EXPECT_EQ(validationMessage(PlanarSceneOptions()), "valid");
  PlanarSceneOptions options;
  options.intensity_noise = 5.0;
  EXPECT_EQ(validationMessage(options),
            "InvalidOptions: PlanarSceneOptions.intensity_noise = 5: must be in [0, 1] (a "
            "fraction of 255)");
  options = PlanarSceneOptions();
  options.num_frames = 1;
  EXPECT_NE(validationMessage(options).find("num_frames = 1"), std::string::npos);
  options = PlanarSceneOptions();
  options.arc_degrees = 360.0;
  EXPECT_NE(validationMessage(options).find("arc_degrees"), std::string::npos);
  options = PlanarSceneOptions();
  options.orbit_radius = 0.0;
  EXPECT_NE(validationMessage(options).find("orbit_radius"), std::string::npos);
  options = PlanarSceneOptions();
  options.init_noise_translation = -1.0;
  EXPECT_NE(validationMessage(options).find("init_noise_translation"), std::string::npos);
  EXPECT_THROW(makePlanarScene(smoothTexture(8, 8), options), InvalidOptions);
}

TEST(PlanarSceneOptions, FramesAreBoundedByTheMemoryTheViewsHold) {
  // 4 GiB of colour views: 4,294,967,296 / (640 x 480 x 3) = 4660.3; 805 MB per 16384^2 view.
  EXPECT_EQ(maxPlanarFrames(640, 480), 4660);
  EXPECT_EQ(maxPlanarFrames(1280, 960), 1165);
  EXPECT_EQ(maxPlanarFrames(16384, 16384), 5);
  EXPECT_EQ(maxPlanarFrames(16, 12), kMaxPlanarFrames);

  PlanarSceneOptions options;
  options.num_frames = 4660;
  EXPECT_EQ(validationMessage(options), "valid");
  options.num_frames = 4661;
  EXPECT_EQ(validationMessage(options),
            "InvalidOptions: PlanarSceneOptions.num_frames = 4661: must be <= 4660 for 640x480 "
            "views (at most 10000, and the views held in memory, frames x width x height x 3 "
            "bytes, within 4 GiB)");
  options.num_frames = 100000;
  EXPECT_THROW(makePlanarScene(smoothTexture(8, 8), options), InvalidOptions);
  options = smallOptions();
  options.width = 16;
  options.height = 12;
  options.num_frames = kMaxPlanarFrames + 1;
  EXPECT_NE(validationMessage(options).find("num_frames = 10001: must be <= 10000 for 16x12"),
            std::string::npos);
}

TEST(PlanarTexture, LongerSideSpansThePlaneWidthCentredWithTopAtPlusY) {
  const PlanarTexture texture = makePlanarTexture(cv::Mat(300, 400, CV_8UC3), 2.0);
  EXPECT_DOUBLE_EQ(texture.width_m, 2.0);
  EXPECT_DOUBLE_EQ(texture.height_m, 1.5);
  const Eigen::Matrix3d m = texture.planeFromTexture();
  // Outer corner of the top-left pixel, and the centre of the photo.
  EXPECT_TRUE((m * Eigen::Vector3d(-0.5, -0.5, 1)).isApprox(Eigen::Vector3d(-1.0, 0.75, 1)));
  EXPECT_TRUE((m * Eigen::Vector3d(199.5, 149.5, 1)).isApprox(Eigen::Vector3d(0, 0, 1)));
  EXPECT_DOUBLE_EQ(makePlanarTexture(cv::Mat(400, 300, CV_8UC1), 2.0).height_m, 2.0);
  EXPECT_THROW(makePlanarTexture(cv::Mat(), 1.0), CheckError);
}

TEST(RenderPlanarView, PixelShowsTheTextureAtThePlanePointItsRayMeets) {
  const cv::Mat photo = smoothTexture(240, 180);
  const PlanarSceneOptions options;
  const PlanarScene scene = makePlanarScene(photo, options);
  std::mt19937 rng(7);
  int checked = 0;
  for (const int frame : {0, 14, 29}) {
    const Pose3& pose = scene.true_cam_from_world[frame];
    std::uniform_int_distribution<int> column(0, options.width - 1), row(0, options.height - 1);
    for (int k = 0; k < 40; ++k) {
      const Eigen::Vector2d pixel(column(rng), row(rng));
      const Eigen::Vector2d uv =
          textureCoordinates(scene.texture, planePointSeenAt(*scene.camera, pose, pixel));
      if (uv.minCoeff() < 0.0 || uv.x() > photo.cols - 2 || uv.y() > photo.rows - 2) continue;
      const cv::Vec3d expected = bilinear(photo, uv);
      const cv::Vec3b rendered = scene.images[frame].at<cv::Vec3b>(int(pixel.y()), int(pixel.x()));
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(rendered[c], expected[c], 1.5)
            << "frame " << frame << " pixel " << pixel.transpose() << " channel " << c;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 90);
}

TEST(RenderPlanarView, AMarkerOnThePlaneAppearsWhereTheCameraProjectsIt) {
  const PlanarSceneOptions options;
  const PlanarScene scene = makePlanarScene(smoothTexture(200, 150), options);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> column(70, 130), row(50, 100);
  for (int k = 0; k < 5; ++k) {
    // A 7x7 texel (35 mm) red square on a grey photo, about 25 px wide in the view.
    cv::Mat photo(150, 200, CV_8UC3, cv::Scalar(100, 100, 100));
    const int u = column(rng), v = row(rng);
    photo(cv::Rect(u - 3, v - 3, 7, 7)).setTo(cv::Scalar(0, 0, 255));
    const Eigen::Vector3d centre = scene.texture.planeFromTexture() * Eigen::Vector3d(u, v, 1);
    const Eigen::Vector3d point(centre.x(), centre.y(), 0.0);
    for (const int frame : {0, 29}) {
      const Pose3& pose = scene.true_cam_from_world[frame];
      Eigen::Vector2d pixel;
      ASSERT_TRUE(scene.camera->project(pose * point, &pixel));
      ASSERT_TRUE(scene.camera->isInImage(pixel, 2.0)) << pixel.transpose();
      const cv::Mat view = renderPlanarView(photo, options.plane_width, *scene.camera, pose);
      const cv::Vec3b seen =
          view.at<cv::Vec3b>(int(std::lround(pixel.y())), int(std::lround(pixel.x())));
      EXPECT_EQ(seen, cv::Vec3b(0, 0, 255)) << "marker at texel " << u << "," << v;
    }
  }
}

TEST(PlanarScene, PixelMapIsTheHomographyBetweenTwoViewsOfThePlane) {
  PlanarSceneOptions options;
  options.num_frames = 5;
  const PlanarScene scene = makePlanarScene(smoothTexture(40, 30), options);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-0.3, 0.3);
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector3d point(coordinate(rng), coordinate(rng), 0.0);
    Eigen::Vector2d in_first, in_last;
    ASSERT_TRUE(scene.camera->project(scene.true_cam_from_world[0] * point, &in_first));
    ASSERT_TRUE(scene.camera->project(scene.true_cam_from_world[4] * point, &in_last));
    const Eigen::Vector3d plane_point(point.x(), point.y(), 1.0);
    EXPECT_LT(
        ((pixelFromPlane(*scene.camera, scene.true_cam_from_world[0]) * plane_point).hnormalized() -
         in_first)
            .norm(),
        1e-9);
    EXPECT_LT(((scene.pixelMap(0, 4) * in_first.homogeneous()).hnormalized() - in_last).norm(),
              1e-9);
  }
  EXPECT_LT((scene.pixelMap(2, 2) - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_THROW(scene.pixelMap(0, 5), CheckError);
}

TEST(RenderPlanarView, RaysMeetingThePlaneBehindTheCameraSeeTheBackground) {
  // A camera 0.5 m above a huge photo looking at the horizon: the lower half sees the plane in
  // front, the upper half's rays meet the plane behind the camera.
  const Camera camera(smallOptions().intrinsics());
  Eigen::Matrix3d world_from_cam;
  world_from_cam << 1, 0, 0,  //
      0, 0, 1,                //
      0, -1, 0;
  const Pose3 cam_from_world = Pose3(world_from_cam, Eigen::Vector3d(0, 0, 0.5)).inverse();
  const cv::Mat view = renderPlanarView(smoothTexture(200, 200), 1000.0, camera, cam_from_world, 7);
  const cv::Mat top = view.rowRange(0, 55);
  EXPECT_EQ(cv::countNonZero(top.reshape(1) != 7), 0);
  EXPECT_GT(cv::countNonZero(view.rowRange(65, 120).reshape(1) != 7), 0);
  // A camera in the plane sees nothing.
  const Pose3 in_plane = Pose3(world_from_cam, Eigen::Vector3d(0, 0, 0)).inverse();
  EXPECT_EQ(cv::countNonZero(
                renderPlanarView(smoothTexture(20, 20), 1.0, camera, in_plane, 0).reshape(1)),
            0);
}

TEST(PlanarScene, OrbitLooksAtThePlaneCentreFromAboveWithABaseline) {
  const PlanarSceneOptions options;
  // An all-white 4:3 photo on a black background: the non-zero pixels are the plane.
  const PlanarScene scene =
      makePlanarScene(cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(255)), options);
  ASSERT_EQ(scene.images.size(), 30u);
  const double step = options.arc_degrees * M_PI / 180.0 / (options.num_frames - 1);
  EXPECT_NEAR(scene.meanFrameBaseline(), 2.0 * options.orbit_radius * std::sin(step / 2), 1e-12);
  EXPECT_NEAR(scene.firstToLastBaseline(), options.orbit_radius * std::sqrt(2.0), 1e-12);
  for (int i = 0; i < options.num_frames; ++i) {
    const Pose3& pose = scene.true_cam_from_world[i];
    const Eigen::Vector3d centre = pose.inverseTranslation();
    EXPECT_NEAR(centre.z(), options.camera_height, 1e-12);
    EXPECT_NEAR(centre.head<2>().norm(), options.orbit_radius, 1e-12);
    Eigen::Vector2d pixel;
    ASSERT_TRUE(scene.camera->project(pose * Eigen::Vector3d::Zero(), &pixel));
    EXPECT_TRUE(pixel.isApprox(Eigen::Vector2d(options.cx, options.cy), 1e-9));
    EXPECT_DOUBLE_EQ(scene.timestamps[i], i / 30.0);
    const double coverage =
        cv::countNonZero(scene.images[i].reshape(1)) / (3.0 * options.width * options.height);
    EXPECT_GT(coverage, 0.8) << "frame " << i;
  }
  // The middle of the arc sees the photo upright: image x along world x, image y along -y.
  const Eigen::Matrix3d rotation = scene.true_cam_from_world[15].rotationMatrix();
  EXPECT_GT(rotation(0, 0), 0.99);
  EXPECT_LT(rotation(1, 1), -0.9);
}

TEST(PlanarScene, IntensityNoiseHasTheAskedStdDev) {
  PlanarSceneOptions options = smallOptions();
  options.num_frames = 2;
  const cv::Mat grey(150, 200, CV_8UC3, cv::Scalar::all(128));
  const PlanarScene clean = makePlanarScene(grey, options);
  options.intensity_noise = 0.05;
  const PlanarScene noisy = makePlanarScene(grey, options);
  double sum = 0.0, sum_squares = 0.0;
  int count = 0;
  for (int i = 0; i < options.num_frames; ++i) {
    const cv::Mat a = clean.images[i].reshape(1), b = noisy.images[i].reshape(1);
    for (int r = 0; r < a.rows; ++r) {
      for (int c = 0; c < a.cols; ++c) {
        if (a.at<uchar>(r, c) != 128) continue;  // the background and the photo's border
        const double d = double(b.at<uchar>(r, c)) - 128.0;
        sum += d;
        sum_squares += d * d;
        ++count;
      }
    }
  }
  ASSERT_GT(count, 50000);
  const double mean = sum / count;
  EXPECT_NEAR(mean, 0.0, 0.2);
  // Rounding adds a variance of 1/12.
  EXPECT_NEAR(std::sqrt(sum_squares / count - mean * mean),
              std::hypot(0.05 * 255, std::sqrt(1.0 / 12)), 0.15);
  // The noise does not touch the geometry.
  EXPECT_TRUE(noisy.initial_cam_from_world[1].translation().isApprox(
      clean.initial_cam_from_world[1].translation()));
}

TEST(PlanarScene, SameSeedGivesTheSameScene) {
  PlanarSceneOptions options = smallOptions();
  options.intensity_noise = 0.1;
  const cv::Mat photo = smoothTexture(64, 48);
  const PlanarScene a = makePlanarScene(photo, options);
  const PlanarScene b = makePlanarScene(photo, options);
  options.seed = 2;
  const PlanarScene c = makePlanarScene(photo, options);
  for (int i = 0; i < options.num_frames; ++i) {
    EXPECT_EQ(cv::norm(a.images[i], b.images[i], cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(a.images[i], c.images[i], cv::NORM_INF), 0.0);
    EXPECT_EQ(a.initial_cam_from_world[i].translation(), b.initial_cam_from_world[i].translation());
    EXPECT_NE(a.initial_cam_from_world[i].translation(), c.initial_cam_from_world[i].translation());
  }
}

// 400 tiny views whose initial poses carry the given error: enough frames for error statistics.
PlanarSceneOptions manyTinyViews(InitNoiseModel model, double translation, double rotation_deg) {
  PlanarSceneOptions options = smallOptions();
  options.width = 16;
  options.height = 12;
  options.num_frames = 400;
  options.init_noise_model = model;
  options.init_noise_translation = translation;
  options.init_noise_rotation_deg = rotation_deg;
  return options;
}

TEST(PlanarScene, InitialPosesDifferFromTruthByTheAskedNoise) {
  PlanarSceneOptions options = manyTinyViews(InitNoiseModel::kIndependent, 0.02, 1.0);
  const PlanarScene scene = makePlanarScene(smoothTexture(16, 12), options);
  double centre_squares = 0.0, angle_squares = 0.0;
  for (int i = 0; i < options.num_frames; ++i) {
    const Pose3& truth = scene.true_cam_from_world[i];
    const Pose3& initial = scene.initial_cam_from_world[i];
    centre_squares += (initial.inverseTranslation() - truth.inverseTranslation()).squaredNorm();
    angle_squares += std::pow(initial.rotation().angularDistance(truth.rotation()), 2);
  }
  // Per axis: rms over 3 axes x 400 frames, within about 3 standard errors.
  EXPECT_NEAR(std::sqrt(centre_squares / (3 * options.num_frames)), 0.02, 0.02 * 0.07);
  EXPECT_NEAR(std::sqrt(angle_squares / (3 * options.num_frames)) * 180 / M_PI, 1.0, 0.07);

  options.init_noise_translation = 0.0;
  options.init_noise_rotation_deg = 0.0;
  options.num_frames = 2;
  const PlanarScene exact = makePlanarScene(smoothTexture(16, 12), options);
  EXPECT_TRUE(exact.initial_cam_from_world[0].translation().isApprox(
      exact.true_cam_from_world[0].translation()));
}

// Drift: the error of every motion between consecutive frames has the asked std dev, and the
// errors of the poses accumulate like a random walk.
TEST(PlanarScene, DriftPerturbsEveryStepAndAccumulates) {
  const PlanarSceneOptions options = manyTinyViews(InitNoiseModel::kDrift, 0.001, 0.05);
  const PlanarScene scene = makePlanarScene(smoothTexture(16, 12), options);
  double angle_squares = 0.0;
  for (int i = 1; i < options.num_frames; ++i) {
    const Pose3 true_step =
        scene.true_cam_from_world[i] * scene.true_cam_from_world[i - 1].inverse();
    const Pose3 initial_step =
        scene.initial_cam_from_world[i] * scene.initial_cam_from_world[i - 1].inverse();
    angle_squares += std::pow(initial_step.rotation().angularDistance(true_step.rotation()), 2);
  }
  EXPECT_NEAR(std::sqrt(angle_squares / (3 * (options.num_frames - 1))) * 180 / M_PI, 0.05,
              0.05 * 0.07);
  // A random walk: the rotation error after n steps grows like sqrt(n) times a step's.
  const auto rotation_error = [&](int i) {
    return scene.initial_cam_from_world[i].rotation().angularDistance(
        scene.true_cam_from_world[i].rotation());
  };
  double early = 0.0, late = 0.0;
  for (int i = 0; i < 20; ++i) early += rotation_error(i) / 20;
  for (int i = 380; i < 400; ++i) late += rotation_error(i) / 20;
  EXPECT_GT(late, 3 * early);
  EXPECT_EQ(parseEnumName<InitNoiseModel>("drift", "PlanarSceneOptions", "f"),
            InitNoiseModel::kDrift);
  EXPECT_EQ(toString(InitNoiseModel::kIndependent), "independent");
  EXPECT_THROW(parseEnumName<InitNoiseModel>("gaussian", "PlanarSceneOptions", "f"),
               InvalidOptions);
}

class PlanarDatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::path(::testing::TempDir()) /
              ("planar_scene_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }
  std::filesystem::path folder_;
};

TEST_F(PlanarDatasetTest, WritesTheTumLayoutThatTheReadersReadBack) {
  PlanarSceneOptions options = smallOptions();
  options.intensity_noise = 0.05;
  const PlanarScene scene = makePlanarScene(smoothTexture(64, 48), options);
  writePlanarDataset(folder_.string(), scene);

  const std::vector<ImageEntry> images = readImageList((folder_ / "rgb.txt").string());
  const std::vector<StampedPose> truth = readTrajectory((folder_ / "groundtruth.txt").string());
  const std::vector<StampedPose> initial = readTrajectory((folder_ / "init_poses.txt").string());
  ASSERT_EQ(images.size(), 3u);
  ASSERT_EQ(truth.size(), 3u);
  ASSERT_EQ(initial.size(), 3u);
  EXPECT_EQ(images[1].path, (folder_ / "rgb/000001.png").string());
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(images[i].timestamp, truth[i].timestamp);
    EXPECT_EQ(images[i].timestamp, initial[i].timestamp);
    EXPECT_NEAR(images[i].timestamp, scene.timestamps[i], 1e-6);
    EXPECT_EQ(cv::norm(readColorImage(images[i].path), scene.images[i], cv::NORM_INF), 0.0);
    // Camera-to-world: the translation is the camera centre.
    EXPECT_TRUE(truth[i].world_from_cam.translation().isApprox(
        scene.true_cam_from_world[i].inverseTranslation(), 1e-8));
    EXPECT_LT(initial[i].world_from_cam.rotation().angularDistance(
                  scene.initial_cam_from_world[i].inverse().rotation()),
              1e-8);
  }
  const Camera camera = readCameraYaml((folder_ / "camera.yaml").string());
  EXPECT_EQ(camera.fx(), options.fx);
  EXPECT_EQ(camera.cx(), options.cx);
  EXPECT_EQ(camera.width(), options.width);
  EXPECT_FALSE(camera.hasDistortion());
}

TEST_F(PlanarDatasetTest, FolderThatIsAFileIsIoErrorNamingIt) {
  std::ofstream(folder_.string()) << "a file";
  const PlanarScene scene = makePlanarScene(smoothTexture(16, 12), smallOptions());
  try {
    writePlanarDataset(folder_.string(), scene);
    ADD_FAILURE() << "nothing thrown";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(folder_.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace curvesfm
