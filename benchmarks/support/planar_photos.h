#pragma once

#include <string>
#include <vector>

namespace curvesfm::bench {

/// Where Debian's opencv-doc package puts OpenCV's sample photos.
inline const char* const kOpenCvSampleData = "/usr/share/doc/opencv-doc/examples/data";

struct PlanarPhoto {
  std::string file;
  std::string category;  ///< "logo", "indoor" or "outdoor".
};

/// The photos of the paper's planar experiment (§4.1), three per category. The paper took its
/// indoor images from TUM RGB-D and its outdoor ones from KITTI; OpenCV's sample data has no such
/// frames, so these are the closest in kind: flat logos with few contours, cluttered rooms, and
/// street scenes / facades. planar_bench runs them; real_bench renders them as sets.
inline const std::vector<PlanarPhoto>& planarPhotos() {
  static const std::vector<PlanarPhoto> photos = {
      {"opencv-logo.png", "logo"}, {"LinuxLogo.jpg", "logo"},      {"WindowsLogo.jpg", "logo"},
      {"left01.jpg", "indoor"},    {"rubberwhale1.png", "indoor"}, {"box_in_scene.png", "indoor"},
      {"building.jpg", "outdoor"}, {"leuvenA.jpg", "outdoor"},     {"graf1.png", "outdoor"}};
  return photos;
}

}  // namespace curvesfm::bench
