#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace curvesfm {

/// One edge pixel of an image, as the curve residual needs it (paper §3.2).
/// Coordinates are pixels, x to the right and y down, with pixel centres on integers (the
/// convention of Camera::project), so the pixel in column c and row r has centre (c, r).
struct EdgePixel {
  /// Centre of the edge pixel: exactly (column, row).
  Eigen::Vector2f pixel = Eigen::Vector2f::Zero();
  /// Sub-pixel edge position: the pixel centre moved along `normal` to the vertex of the parabola
  /// through the logarithms of the gradient magnitudes at the pixel and at its two 8-neighbours
  /// along the gradient direction (a Gaussian fit of the magnitude profile across the edge), the
  /// shift clamped to [-0.5, 0.5] px. Equal to `pixel` where the profile has no maximum (flat or
  /// convex) or a neighbour lies outside the image.
  Eigen::Vector2f subpixel = Eigen::Vector2f::Zero();
  /// Unit image gradient direction at the edge pixel (the edge normal, pointing dark to bright).
  Eigen::Vector2f normal = Eigen::Vector2f(1.0f, 0.0f);
};

struct NearestEdgeFieldOptions {
  /// Reach R of the field (px): pixels whose Euclidean distance to the nearest edge pixel centre
  /// is at most R hold that edge pixel; farther ones hold none. 1 <= R <= 1000.
  int max_distance_px = 15;

  /// Throws InvalidOptions naming the field, its value and the constraint.
  void validate() const;
};

/// The nearest-edge field of one keyframe (paper §3.2): for every pixel within R px of an edge,
/// the nearest edge pixel (exact Euclidean distance between pixel centres; ties broken
/// arbitrarily but deterministically) with its sub-pixel position and unit gradient.
///
/// Built once per keyframe in O(pixels) by an exact separable distance transform that carries the
/// argmin (per row: the nearest edge pixel in each column, then the best column by a bounded
/// window search or the lower envelope of parabolas); docs/benchmarks.md compares it with
/// cv::distanceTransform. Memory: 2 bytes per pixel (an index into the edge list) for an image
/// of fewer than 65,535 edge pixels, 4 for more, plus 24 bytes per edge pixel. Immutable after
/// construction, so lookups are thread-safe.
class NearestEdgeField {
 public:
  /// An empty 0 x 0 field (every lookup misses).
  NearestEdgeField() = default;

  /// Builds the field from an edge mask and the image gradients.
  /// `edges`: CV_8UC1, non-zero marks an edge pixel (e.g. the output of cv::Canny).
  /// `grad_x`, `grad_y`: CV_16SC1 or CV_32FC1 (both the same type), the same size as `edges`
  /// (e.g. cv::Sobel); their direction at an edge pixel gives the normal and their magnitude the
  /// sub-pixel fit. An edge pixel with a zero gradient gets normal (1, 0) and no sub-pixel shift.
  /// Throws CheckError on mismatched sizes or types, InvalidOptions on bad options.
  static NearestEdgeField build(const cv::Mat& edges, const cv::Mat& grad_x, const cv::Mat& grad_y,
                                const NearestEdgeFieldOptions& options = {});

  int width() const { return width_; }
  int height() const { return height_; }
  int maxDistance() const { return max_distance_px_; }

  /// The nearest edge pixel to the pixel whose centre is closest to (x, y), i.e. pixel
  /// (round(x), round(y)); nullptr if that pixel is outside the image, beyond the reach R, or
  /// (x, y) is not finite. Allocation-free and exception-free: meant for the inner loop.
  const EdgePixel* nearest(double x, double y) const {
    if (!contains(x, y)) return nullptr;
    return nearestToPixel(static_cast<int>(x + 0.5), static_cast<int>(y + 0.5));
  }

  /// A hint that nearest(x, y) is coming: starts loading its cache line, so that a caller with
  /// other work to do meanwhile does not wait for the miss. No effect outside the image.
  void prefetch(double x, double y) const {
    if (!contains(x, y)) return;
    const std::size_t pixel =
        static_cast<std::size_t>(static_cast<int>(y + 0.5)) * width_ + static_cast<int>(x + 0.5);
    if (narrow_index_.empty()) {
      __builtin_prefetch(&wide_index_[pixel]);
    } else {
      __builtin_prefetch(&narrow_index_[pixel]);
    }
  }

  /// True if (x, y) rounds to a pixel of the image, i.e. lies in (-0.5, width - 0.5) x
  /// (-0.5, height - 0.5); false for non-finite coordinates.
  bool contains(double x, double y) const {
    return x > -0.5 && y > -0.5 && x < width_ - 0.5 && y < height_ - 0.5;
  }

  /// The nearest edge pixel to pixel (column, row), or nullptr outside the image or beyond R.
  const EdgePixel* nearestToPixel(int column, int row) const {
    if (column < 0 || row < 0 || column >= width_ || row >= height_) return nullptr;
    const std::size_t pixel = static_cast<std::size_t>(row) * width_ + column;
    if (narrow_index_.empty()) {
      const std::int32_t index = wide_index_[pixel];
      return index < 0 ? nullptr : &edges_[static_cast<std::size_t>(index)];
    }
    const std::uint16_t index = narrow_index_[pixel];
    return index == kNoNarrowIndex ? nullptr : &edges_[index];
  }

  /// All edge pixels, in row-major order of their pixels.
  const std::vector<EdgePixel>& edges() const { return edges_; }

  /// Bytes held by the field (index map plus edge list).
  std::size_t memoryBytes() const {
    return narrow_index_.capacity() * sizeof(std::uint16_t) +
           wide_index_.capacity() * sizeof(std::int32_t) + edges_.capacity() * sizeof(EdgePixel);
  }

 private:
  // Leaves value-initialised elements (resize) uninitialised: build() writes every entry, and
  // zeroing megabytes first would cost about 5 % of it.
  template <class T>
  struct UninitialisedAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
      using other = UninitialisedAllocator<U>;
    };
    UninitialisedAllocator() = default;
    template <class U>
    UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
    template <class U>
    void construct(U* p) noexcept {
      ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
      ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
  };

  int width_ = 0;
  int height_ = 0;
  int max_distance_px_ = 0;
  // Per pixel, row-major: index into edges_. Two bytes a pixel (kNoNarrowIndex beyond R) when
  // the image has fewer edge pixels than that, which halves the field of a real image; else four
  // (-1 beyond R). Exactly one of the two is filled.
  static constexpr std::uint16_t kNoNarrowIndex = 0xFFFF;
  std::vector<std::uint16_t, UninitialisedAllocator<std::uint16_t>> narrow_index_;
  std::vector<std::int32_t, UninitialisedAllocator<std::int32_t>> wide_index_;
  std::vector<EdgePixel> edges_;
};

}  // namespace curvesfm
