#include "frontend/image/absolute_pose.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "core/check.h"
#include "core/errors.h"
#include "core/so3.h"

namespace curvesfm {

void AbsolutePoseOptions::validate() const {
  const OptionCheck require("AbsolutePoseOptions");
  require.positive("max_reprojection_error_px", max_reprojection_error_px);
  require(confidence > 0.0 && confidence < 1.0, "confidence", confidence, "in (0, 1)");
  require(max_iterations >= 1, "max_iterations", max_iterations, ">= 1");
  require(min_inliers >= 4, "min_inliers", min_inliers, ">= 4");
  require(min_inlier_ratio >= 0.0 && min_inlier_ratio <= 1.0, "min_inlier_ratio", min_inlier_ratio,
          "in [0, 1]");
}

namespace {

Pose3 poseFromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  const Eigen::Vector3d r(rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2));
  const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  return Pose3(so3::exp(r), t);
}

// Inliers of a pose by reprojection error, the same test RANSAC used.
int countInliers(const Camera& camera, const Pose3& cam_from_world,
                 const std::vector<Eigen::Vector3d>& points,
                 const std::vector<Eigen::Vector2d>& pixels, double threshold_px,
                 std::vector<std::uint8_t>* inliers) {
  inliers->assign(points.size(), 0);
  int count = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    Eigen::Vector2d projected;
    if (!camera.project(cam_from_world * points[i], &projected)) continue;
    if ((projected - pixels[i]).norm() > threshold_px) continue;
    (*inliers)[i] = 1;
    ++count;
  }
  return count;
}

}  // namespace

AbsolutePose estimateAbsolutePose(const Camera& camera, const std::vector<Eigen::Vector3d>& points,
                                  const std::vector<Eigen::Vector2d>& pixels,
                                  const AbsolutePoseOptions& options) {
  options.validate();
  CURVESFM_CHECK(points.size() == pixels.size())
      << points.size() << " points but " << pixels.size() << " pixels";
  AbsolutePose result;
  result.inliers.assign(points.size(), 0);
  const int n = static_cast<int>(points.size());
  if (n < options.min_inliers || n < 4) {
    result.rejection = AbsolutePoseRejection::kTooFewMatches;
    return result;
  }
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (int i = 0; i < n; ++i) {
    object.emplace_back(points[i].x(), points[i].y(), points[i].z());
    image.emplace_back(pixels[i].x(), pixels[i].y());
  }
  cv::Mat K;
  cv::eigen2cv(camera.K(), K);
  cv::Mat rvec, tvec;
  std::vector<int> ransac_inliers;
  // RANSAC's generator is OpenCV's global one: seed it so the same input gives the same pose.
  cv::theRNG().state = 0x12345678;
  const bool found = cv::solvePnPRansac(object, image, K, cv::noArray(), rvec, tvec, false,
                                        options.max_iterations, options.max_reprojection_error_px,
                                        options.confidence, ransac_inliers, cv::SOLVEPNP_AP3P);
  if (!found || ransac_inliers.size() < 4) {
    result.rejection = AbsolutePoseRejection::kNoModel;
    return result;
  }
  // Refine on RANSAC's inliers, then count inliers again at the refined pose.
  std::vector<cv::Point3d> inlier_object;
  std::vector<cv::Point2d> inlier_image;
  for (int i : ransac_inliers) {
    inlier_object.push_back(object[i]);
    inlier_image.push_back(image[i]);
  }
  cv::solvePnPRefineLM(inlier_object, inlier_image, K, cv::noArray(), rvec, tvec);
  result.cam_from_world = poseFromRvecTvec(rvec, tvec);
  result.num_inliers = countInliers(camera, result.cam_from_world, points, pixels,
                                    options.max_reprojection_error_px, &result.inliers);
  if (result.num_inliers < options.min_inliers) {
    result.rejection = AbsolutePoseRejection::kTooFewInliers;
  } else if (result.num_inliers < options.min_inlier_ratio * n) {
    result.rejection = AbsolutePoseRejection::kLowInlierRatio;
  } else {
    result.accepted = true;
  }
  return result;
}

}  // namespace curvesfm
