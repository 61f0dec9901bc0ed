#include "core/nearest_edge_field.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

// Row of the "no edge" sentinel above (negated) and below every image: far enough that its
// distance exceeds any reach, small enough that r +- kFarRow never overflows.
constexpr std::int32_t kFarRow = 1 << 29;

// The hot loops are compiled twice where the compiler can dispatch at run time (GCC/Clang on
// x86-64 ELF): the build's baseline is SSE2, and AVX2 (twice the lanes, blend and gather
// instructions) makes the whole build about twice as fast on sparse edge maps.
#if defined(__x86_64__) && defined(__ELF__) && (defined(__GNUC__) || defined(__clang__))
#define CURVESFM_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CURVESFM_AVX2_CLONES
#endif

// ln(value) for value >= 0 to about 1e-6 relative, a few times cheaper than std::log: the
// exponent plus the atanh series of the mantissa folded into [sqrt(1/2), sqrt(2)). Zero gives
// about -88 (finite), which keeps the sub-pixel fit free of infinities.
float fastLog(float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  // Mantissas above sqrt(2) are halved (exponent + 1) so that the series converges fast.
  const std::uint32_t fold = (bits & 0x007FFFFFu) > 0x003504F3u ? 1u : 0u;
  const int exponent = static_cast<int>(bits >> 23) - 127 + static_cast<int>(fold);
  bits = (bits & 0x007FFFFFu) | (0x3F800000u - (fold << 23));
  float mantissa;
  std::memcpy(&mantissa, &bits, sizeof(mantissa));
  const float y = (mantissa - 1.0f) / (mantissa + 1.0f);
  const float y2 = y * y;
  constexpr float kLn2 = 0.69314718f;
  return static_cast<float>(exponent) * kLn2 +
         2.0f * y * (1.0f + y2 * (1.0f / 3.0f + y2 * (1.0f / 5.0f + y2 * (1.0f / 7.0f))));
}

// Gradient rows above, at and below one image row; at the image border the missing ones alias
// the middle one and contains() is false for them.
template <class T>
struct GradientRows {
  GradientRows(const cv::Mat& grad_x, const cv::Mat& grad_y, int row)
      : row_(row), width_(grad_x.cols), height_(grad_x.rows) {
    for (int k = 0; k < 3; ++k) {
      const int clamped = std::clamp(row + k - 1, 0, height_ - 1);
      x_[k] = grad_x.ptr<T>(clamped);
      y_[k] = grad_y.ptr<T>(clamped);
    }
  }

  bool contains(int row_offset, int column) const {
    const int row = row_ + row_offset;
    return column >= 0 && column < width_ && row >= 0 && row < height_;
  }
  float x(int column) const { return static_cast<float>(x_[1][column]); }
  float y(int column) const { return static_cast<float>(y_[1][column]); }
  float squaredMagnitude(int row_offset, int column) const {
    const float gx = static_cast<float>(x_[1 + row_offset][column]);
    const float gy = static_cast<float>(y_[1 + row_offset][column]);
    return gx * gx + gy * gy;
  }

 private:
  int row_;
  int width_;
  int height_;
  const T* x_[3];
  const T* y_[3];
};

// 1 / sqrt(value) for value > 0 to float precision: the bit-level first guess refined by three
// Newton steps. Unlike std::sqrt (errno) it lets the fit loop vectorise.
float inverseSqrt(float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  bits = 0x5F375A86u - (bits >> 1);
  float estimate;
  std::memcpy(&estimate, &bits, sizeof(estimate));
  const float half = 0.5f * value;
  estimate *= 1.5f - half * estimate * estimate;  // Written out: a loop here blocks vectorising.
  estimate *= 1.5f - half * estimate * estimate;
  estimate *= 1.5f - half * estimate * estimate;
  return estimate;
}

// The fit of RowFitter, on arrays that do not overlap (hence __restrict). Branch-free (selects,
// divisors kept away from zero without a comparison) and in two loops (one loop gets its
// selects threaded into branches by the compiler), so that both vectorise.
CURVESFM_AVX2_CLONES
void fitProfiles(int count, const float* __restrict gx, const float* __restrict gy,
                 const float* __restrict step_x, const float* __restrict step_y,
                 const float* __restrict before, const float* __restrict after,
                 float* __restrict normal_x, float* __restrict normal_y, float* __restrict offset) {
  for (int i = 0; i < count; ++i) {  // The vertex, in steps.
    const float log_before = fastLog(before[i]);
    const float log_center = fastLog(gx[i] * gx[i] + gy[i] * gy[i]);
    const float log_after = fastLog(after[i]);
    const float curvature = log_before - 2.0f * log_center + log_after;
    const float concave = curvature < 0.0f ? 0.5f : 0.0f;
    offset[i] = concave * (log_before - log_after) / std::min(curvature, -1e-30f);
  }
  for (int i = 0; i < count; ++i) {
    const float squared = gx[i] * gx[i] + gy[i] * gy[i];
    // The tiny bias keeps 1/sqrt finite at zero, where the normal becomes (1, 0).
    const float inverse = inverseSqrt(squared + 1e-30f);
    const float flat = squared > 0.0f ? 0.0f : 1.0f;
    const float nx = gx[i] * inverse + flat;
    const float ny = gy[i] * inverse;
    normal_x[i] = nx;
    normal_y[i] = ny;
    offset[i] = std::clamp(offset[i] * (step_x[i] * nx + step_y[i] * ny), -0.5f, 0.5f);
  }
}

// Normals and sub-pixel positions of the edge pixels of one row, computed in three loops so that
// the arithmetic vectorises: gather the gradients, fit, write the edge pixels.
//
// The magnitude profile is sampled at the pixel and its two neighbours along the gradient
// quantised to the 8-neighbourhood, step s. A smooth step edge has a Gaussian-like gradient
// profile, so the parabola goes through the logarithms of the magnitudes (a Gaussian fit, exact
// for a Gaussian profile; on blurred steps it is about twice as accurate as a parabola through
// the magnitudes themselves, and bilinear sampling along the exact normal is worse than both,
// see the sub-pixel test). For a straight edge the magnitude depends only on the distance along
// the normal n, so a vertex k steps from the pixel lies k (s . n) px from it along n; s . n is
// |s| cos(quantisation angle), which also accounts for the sqrt(2) of a diagonal step.
template <class T>
class RowFitter {
 public:
  explicit RowFitter(int width)
      : column_(width),
        gx_(width),
        gy_(width),
        step_x_(width),
        step_y_(width),
        before_(width),
        after_(width),
        normal_x_(width),
        normal_y_(width),
        offset_(width) {}

  // Appends the edge pixels of one row (non-zero in `mask`) to `out`, left to right, and their
  // columns to `columns`.
  void fitRow(const std::uint8_t* mask, const GradientRows<T>& rows, int row, int width, int height,
              std::vector<EdgePixel>* out, std::vector<std::int32_t>* columns) {
    const int count = findEdges(mask, width);
    columns->insert(columns->end(), column_.begin(), column_.begin() + count);
    gather(rows, count, row > 0 && row < height - 1, width);
    fitProfiles(count, gx_.data(), gy_.data(), step_x_.data(), step_y_.data(), before_.data(),
                after_.data(), normal_x_.data(), normal_y_.data(), offset_.data());
    const std::size_t first = out->size();
    out->resize(first + static_cast<std::size_t>(count));  // Within the reserved capacity.
    EdgePixel* edges = out->data() + first;
    for (int i = 0; i < count; ++i) {
      const float x = static_cast<float>(column_[i]);
      const float y = static_cast<float>(row);
      edges[i].pixel = Eigen::Vector2f(x, y);
      edges[i].normal = Eigen::Vector2f(normal_x_[i], normal_y_[i]);
      edges[i].subpixel =
          Eigen::Vector2f(x + offset_[i] * normal_x_[i], y + offset_[i] * normal_y_[i]);
    }
  }

 private:
  // The columns of the edge pixels, by branch-free compaction (edge pixels in a dense map are
  // unpredictable); masks are mostly zero, so all-zero runs of eight bytes are skipped.
  int findEdges(const std::uint8_t* mask, int width) {
    int* columns = column_.data();
    int count = 0;
    int column = 0;
    for (; column + 8 <= width; column += 8) {
      std::uint64_t chunk;
      std::memcpy(&chunk, mask + column, sizeof(chunk));
      if (chunk == 0) continue;
      for (int k = column; k < column + 8; ++k) {
        columns[count] = k;
        count += mask[k] != 0 ? 1 : 0;
      }
    }
    for (; column < width; ++column) {
      columns[count] = column;
      count += mask[column] != 0 ? 1 : 0;
    }
    return count;
  }

  // Each edge pixel's gradient, its step s (branch-free: directions are random) and the squared
  // magnitudes at the pixel -s and +s.
  void gather(const GradientRows<T>& rows, int count, bool interior_row, int width) {
    constexpr float kTanEighthPi = 0.41421356f;  // tan(22.5 deg): axis or diagonal.
    const int* columns = column_.data();
    float* gx_out = gx_.data();
    float* gy_out = gy_.data();
    float* step_x_out = step_x_.data();
    float* step_y_out = step_y_.data();
    float* before_out = before_.data();
    float* after_out = after_.data();
    for (int i = 0; i < count; ++i) {
      const int column = columns[i];
      const float gx = rows.x(column);
      const float gy = rows.y(column);
      const float ax = std::abs(gx);
      const float ay = std::abs(gy);
      // A zero gradient gives step 0, hence three equal samples: a flat profile, no shift.
      // Masks rather than conditionals, which the compiler would turn into branches.
      const int keep_x = -static_cast<int>(kTanEighthPi * ay <= ax);
      const int keep_y = -static_cast<int>(kTanEighthPi * ax <= ay);
      const int step_x = keep_x & ((gx > 0.0f) - (gx < 0.0f));
      const int step_y = keep_y & ((gy > 0.0f) - (gy < 0.0f));
      const float squared = gx * gx + gy * gy;
      float before = squared;  // Flat where a neighbour is outside the image.
      float after = squared;
      const bool interior = interior_row && column > 0 && column < width - 1;
      if (interior ||
          (rows.contains(-step_y, column - step_x) && rows.contains(step_y, column + step_x))) {
        before = rows.squaredMagnitude(-step_y, column - step_x);
        after = rows.squaredMagnitude(step_y, column + step_x);
      }
      gx_out[i] = gx;
      gy_out[i] = gy;
      step_x_out[i] = static_cast<float>(step_x);
      step_y_out[i] = static_cast<float>(step_y);
      before_out[i] = before;
      after_out[i] = after;
    }
  }

  std::vector<int> column_;
  std::vector<float> gx_;
  std::vector<float> gy_;
  std::vector<float> step_x_;
  std::vector<float> step_y_;
  std::vector<float> before_;  // Squared gradient magnitudes at the pixel - s and + s.
  std::vector<float> after_;
  std::vector<float> normal_x_;
  std::vector<float> normal_y_;
  std::vector<float> offset_;  // Sub-pixel shift along the normal (px).
};

// Asks for a row of memory ahead of use. The fit reads the gradients around scattered edge
// pixels, a pattern the hardware prefetchers miss; without this, large images spend about a
// sixth of the build waiting for gradient rows.
void prefetchRow(const std::uint8_t* row, std::size_t bytes) {
#if defined(__GNUC__) || defined(__clang__)
  for (std::size_t offset = 0; offset < bytes; offset += 64) __builtin_prefetch(row + offset);
#else
  static_cast<void>(row);
  static_cast<void>(bytes);
#endif
}

// Where the edge pixels are, for the distance transform: row_start[r] is the index of the first
// edge pixel in row r (height + 1 entries), column[e] the column of edge pixel e.
struct EdgeLayout {
  std::vector<std::int32_t> row_start;
  std::vector<std::int32_t> column;
};

// Appends the edge pixels to `out` in row-major order and returns their layout.
template <class T>
EdgeLayout collectEdges(const cv::Mat& edges, const cv::Mat& grad_x, const cv::Mat& grad_y,
                        std::vector<EdgePixel>* out) {
  const std::size_t count = static_cast<std::size_t>(cv::countNonZero(edges));
  out->reserve(count);
  EdgeLayout layout;
  layout.row_start.assign(static_cast<std::size_t>(edges.rows) + 1, 0);
  layout.column.reserve(count);
  RowFitter<T> fitter(edges.cols);
  constexpr int kPrefetchRows = 2;
  for (int row = 0; row < edges.rows; ++row) {
    if (row + kPrefetchRows < edges.rows) {
      prefetchRow(grad_x.ptr(row + kPrefetchRows), grad_x.cols * sizeof(T));
      prefetchRow(grad_y.ptr(row + kPrefetchRows), grad_y.cols * sizeof(T));
    }
    layout.row_start[row] = static_cast<std::int32_t>(out->size());
    fitter.fitRow(edges.ptr<std::uint8_t>(row), GradientRows<T>(grad_x, grad_y, row), row,
                  edges.cols, edges.rows, out, &layout.column);
  }
  layout.row_start[edges.rows] = static_cast<std::int32_t>(out->size());
  return layout;
}

// `index` if `within`, else -1, without a branch: pixels within and beyond R interleave
// unpredictably.
std::int32_t indexWithinReach(std::int32_t index, bool within) {
  return index | (static_cast<std::int32_t>(within) - 1);
}

// Columns per block of the window search (see DistanceSweep).
constexpr int kWindowBlock = 64;

// For every column, the nearest edge pixel in that column above (up_*) or below (down_*) the
// row: squared distance, clamped to beyond = R + 1 (which keeps squares from overflowing and
// marks the column as no site), in int32 and int16, and its index. Branch-free and on
// non-overlapping arrays, so that it vectorises.
CURVESFM_AVX2_CLONES
void nearestInColumns(int row, int width, std::int32_t beyond,
                      const std::int32_t* __restrict up_row,
                      const std::int32_t* __restrict down_row,
                      const std::int32_t* __restrict up_index,
                      const std::int32_t* __restrict down_index, std::int32_t* __restrict squared,
                      std::int16_t* __restrict squared16, std::int32_t* __restrict vertical_index) {
  for (int c = 0; c < width; ++c) {
    const std::int32_t up = row - up_row[c];
    const std::int32_t down = down_row[c] - row;
    const std::int32_t nearest = std::min(std::min(up, down), beyond);
    squared[c] = nearest * nearest;
    squared16[c] = static_cast<std::int16_t>(std::min(nearest * nearest, 32767));
    const std::int32_t from_up = up_index[c];
    const std::int32_t from_down = down_index[c];
    vertical_index[c] = up <= down ? from_up : from_down;
  }
}

// The window search on one block of kWindowBlock columns: the minimum over |k| <= passes of
// squared[i + k] + k^2, grown k = 1, 2, ... until no farther column can change it; then out[i]
// (i < count) is the minimising column's vertical_index, or -1 beyond the reach. `floor` is a
// lower bound of `squared` over every column the search may reach, so columns farther than k
// offer at least (k + 1)^2 + floor: the block is settled once every minimum is at most that, or
// that exceeds R^2. `squared` must be readable from -passes to kWindowBlock + passes,
// vertical_index over the columns the search may pick. False (nothing written) if `passes` do
// not settle the block.
CURVESFM_AVX2_CLONES
bool searchWindow(const std::int16_t* __restrict squared,
                  const std::int32_t* __restrict vertical_index, int count, int passes, int reach,
                  int floor, std::int32_t* __restrict out) {
  std::int16_t best[kWindowBlock];
  std::int16_t from[kWindowBlock];  // Offset of the minimising column.
  for (int i = 0; i < kWindowBlock; ++i) {
    best[i] = squared[i];
    from[i] = 0;
  }
  const int reach_squared = reach * reach;
  for (int k = 1; k <= passes; ++k) {
    const auto pass = [&](const std::int16_t* shifted, std::int16_t offset) {
      const std::int16_t added = static_cast<std::int16_t>(k * k);
      for (int i = 0; i < kWindowBlock; ++i) {
        const std::int16_t candidate = static_cast<std::int16_t>(shifted[i] + added);
        const bool better = candidate < best[i];
        best[i] = better ? candidate : best[i];
        from[i] = better ? offset : from[i];
      }
    };
    // Left before right, both strict: ties go to the leftmost, deterministically.
    pass(squared - k, static_cast<std::int16_t>(-k));
    pass(squared + k, static_cast<std::int16_t>(k));
    const int bound = (k + 1) * (k + 1) + floor;
    bool settled = bound > reach_squared;
    // Blocks settle within a few passes or late; checking every pass after the first few would
    // cost more than it saves.
    if (!settled && (k <= 4 || k % 4 == 0 || k == passes)) {
      std::int16_t worst = 0;
      for (int i = 0; i < kWindowBlock; ++i) worst = std::max(worst, best[i]);
      settled = worst <= bound;
    }
    if (settled) {
      for (int i = 0; i < count; ++i) {
        out[i] = indexWithinReach(vertical_index[i + from[i]], best[i] <= reach_squared);
      }
      return true;
    }
  }
  return false;
}

// The distance transform with argmin, as two separable exact passes (Meijster et al. 2000):
// a column pass gives, for every pixel, the nearest edge pixel in its own column (vertical
// distance g); a row pass minimises (x - c)^2 + g(c)^2 over the columns c of the row, and the
// minimiser c* makes (c*, its column's nearest edge pixel) the exact nearest edge pixel. The
// column pass runs incrementally, row by row, so that both passes stream through the image once
// and scratch memory is O(width + edges).
//
// The row pass has two exact methods, chosen per block of kBlock columns:
//  - the window search (searchWindow): the minimum over |x - c| <= k, grown k = 1, 2, ... in
//    SIMD passes over the block until no farther column can change it. It needs at most R
//    passes, so with R <= kMaxPasses (the default R = 15) it settles every block; dense edges
//    settle it in two or three;
//  - the lower envelope of the parabolas (Meijster), O(1) per column whatever R, from the sites
//    within R of the block, for blocks the window search does not settle in kMaxPasses.
// Blocks with no column near an edge pixel within R of them are beyond reach and skipped. A
// block uses the method that worked for it in the row above (rows are alike), and every
// kRetryRows rows the window search is tried again everywhere.
class DistanceSweep {
 public:
  DistanceSweep(const EdgeLayout& layout, int width, int height, int reach)
      : column_(layout.column),
        row_start_(layout.row_start),
        width_(width),
        height_(height),
        reach_(reach),
        blocks_((width + kBlock - 1) / kBlock),
        // Capped squares must stay exact in int16: (R + 1)^2 + kMaxPasses^2 < 2^15.
        window_enabled_(reach <= kMaxWindowReach),
        max_passes_(std::min(reach, kMaxPasses)),
        up_row_(width, -kFarRow),
        up_index_(width, -1),
        down_row_(width, kFarRow),
        down_index_(width, -1),
        next_in_column_(layout.column.size(), -1),
        next_row_(layout.column.size(), kFarRow),
        squared_(width),
        vertical_index_(width),
        window_squared_(kMaxPasses + blocks_ * kBlock + kMaxPasses, cappedSquare(reach + 1)),
        window_easy_(blocks_, 1),
        block_floor_(blocks_),
        near_floor_(blocks_),
        site_(width),
        site_start_(width),
        site_value_(width),
        owner_(width),
        row_out_(width) {
    // Each column's first edge pixel, and each edge pixel's successor in its column.
    for (int row = height; row-- > 0;) {
      for (int e = row_start_[row + 1]; e-- > row_start_[row];) {
        const int column = column_[e];
        next_in_column_[e] = down_index_[column];
        next_row_[e] = down_row_[column];
        down_index_[column] = e;
        down_row_[column] = row;
      }
    }
  }

  // Hands each row's nearest edge pixels (index into the layout's edge pixels, or -1 beyond R)
  // to store(row, values) as it is done: one row of scratch, so that the caller keeps only the
  // index width it needs (most fields keep two bytes a pixel, and a full-size four-byte
  // temporary was a megabyte of fresh memory per 640 x 480 keyframe).
  template <class Store>
  void run(Store store) {
    std::int32_t* out = row_out_.data();
    for (int row = 0; row < height_; ++row) {
      const int first = row_start_[row];
      const int last = row_start_[row + 1];
      for (int e = first; e < last; ++e) {
        up_row_[column_[e]] = row;
        up_index_[column_[e]] = e;
      }
      if (hasEdgeWithinReach(row)) {
        columnPass(row);
        rowPass(row, out);
      } else {
        std::fill(out, out + width_, -1);
      }
      store(row, static_cast<const std::int32_t*>(out));
      for (int e = first; e < last; ++e) {
        down_index_[column_[e]] = next_in_column_[e];
        down_row_[column_[e]] = next_row_[e];
      }
    }
  }

 private:
  static constexpr int kBlock = kWindowBlock;
  // Window passes before a block falls back to the envelope: about where the envelope becomes
  // the cheaper method (measured with SSE2 and with AVX2). Also the padding of window_squared_.
  static constexpr int kMaxPasses = 16;
  static constexpr int kMaxWindowReach = 127;
  static constexpr int kRetryRows = 8;

  static std::int16_t cappedSquare(int value) {
    return static_cast<std::int16_t>(std::min(value * value, 32767));
  }

  bool hasEdgeWithinReach(int row) const {
    const int top = std::max(0, row - reach_);
    const int bottom = std::min(height_, row + reach_ + 1);
    return row_start_[bottom] > row_start_[top];
  }

  void columnPass(int row) {
    nearestInColumns(row, width_, reach_ + 1, up_row_.data(), down_row_.data(), up_index_.data(),
                     down_index_.data(), squared_.data(), window_squared_.data() + kMaxPasses,
                     vertical_index_.data());
  }

  void rowPass(int row, std::int32_t* out) {
    computeBlockFloors();
    const bool retry = row % kRetryRows == 0;
    int hard_begin = -1;  // First block of the current run of envelope blocks.
    const auto finishHardRun = [&](int end_block) {
      if (hard_begin >= 0) envelope(hard_begin * kBlock, std::min(end_block * kBlock, width_), out);
      hard_begin = -1;
    };
    for (int b = 0; b < blocks_; ++b) {
      if (near_floor_[b] > reach_ * reach_) {
        finishHardRun(b);
        std::fill(out + b * kBlock, out + std::min((b + 1) * kBlock, width_), -1);
        continue;
      }
      if (window_enabled_ && (window_easy_[b] || retry)) {
        window_easy_[b] = windowBlock(b, out) ? 1 : 0;
        if (window_easy_[b]) {
          finishHardRun(b);
          continue;
        }
      }
      if (hard_begin < 0) hard_begin = b;
    }
    finishHardRun(blocks_);
  }

  // near_floor_[b]: no column within R of block b is nearer than this (squared) to an edge pixel.
  // Above R^2 the block is beyond reach: large empty regions are common (more than half the
  // pixels of a typical Canny map are beyond R = 15 px) and the row pass skips them. Otherwise
  // it lets the window search stop early.
  void computeBlockFloors() {
    const std::int32_t* squared = squared_.data();
    for (int b = 0; b < blocks_; ++b) {
      const int begin = b * kBlock;
      const int end = std::min(begin + kBlock, width_);
      std::int32_t smallest = (reach_ + 1) * (reach_ + 1);
      for (int c = begin; c < end; ++c) smallest = std::min(smallest, squared[c]);
      block_floor_[b] = smallest;
    }
    const int span = (reach_ + kBlock - 1) / kBlock;
    for (int b = 0; b < blocks_; ++b) {
      std::int32_t smallest = (reach_ + 1) * (reach_ + 1);
      for (int n = std::max(0, b - span); n <= std::min(blocks_ - 1, b + span); ++n) {
        smallest = std::min(smallest, block_floor_[n]);
      }
      near_floor_[b] = smallest;
    }
  }

  // The window search on block b; false (nothing written) if it needs more than max_passes_.
  bool windowBlock(int b, std::int32_t* out) {
    const int begin = b * kBlock;
    return searchWindow(window_squared_.data() + kMaxPasses + begin, vertical_index_.data() + begin,
                        std::min(kBlock, width_ - begin), max_passes_, reach_, near_floor_[b],
                        out + begin);
  }

  // 32-bit arithmetic is exact up to this width (squares of column differences plus R^2 fit an
  // int32; the separation's numerator, below 2 width^2 + R^2, fits a uint32) and faster.
  static constexpr int kMaxNarrowWidth = 32767;

  void envelope(int begin, int end, std::int32_t* out) {
    if (width_ <= kMaxNarrowWidth) {
      envelope<std::int32_t, std::uint32_t>(begin, end, out);
    } else {
      envelope<std::int64_t, std::uint64_t>(begin, end, out);
    }
  }

  // Meijster's lower envelope for the columns [begin, end), from the sites within R of them,
  // then the owner of every column by a running maximum over the segment starts (sites increase
  // along the envelope), which keeps the write-out free of unpredictable branches.
  template <class Int, class Unsigned>
  void envelope(int begin, int end, std::int32_t* out) {
    const int lo = std::max(0, begin - reach_);
    const int hi = std::min(width_, end + reach_);
    const std::int32_t* squared = squared_.data();
    const Int reach_squared = static_cast<Int>(reach_) * reach_;
    std::int32_t* site = site_.data();
    std::int32_t* site_start = site_start_.data();
    std::int32_t* site_value = site_value_.data();
    // The stack of envelope sites, its top also held in registers: most columns only compare
    // with the top, and reloading it would wait on the store just made.
    int top = -1;
    int top_site = 0;
    int top_start = 0;
    Int top_value = 0;
    for (int c = lo; c < hi; ++c) {
      const Int value = squared[c];
      if (value > reach_squared) continue;
      while (top >= 0) {
        const Int to_top = top_start - top_site;
        const Int to_new = top_start - c;
        if (to_top * to_top + top_value <= to_new * to_new + value) break;
        if (--top >= 0) {
          top_site = site[top];
          top_start = site_start[top];
          top_value = site_value[top];
        }
      }
      int start = lo;
      if (top >= 0) {
        // Last column where the top site is at least as close as c, relative to lo; at least
        // its start column, where the top site wins, so the quotient is non-negative.
        const Unsigned numerator =
            static_cast<Unsigned>(c - top_site) * static_cast<Unsigned>(c + top_site - 2 * lo) +
            static_cast<Unsigned>(value - top_value);
        start = lo + 1 + static_cast<int>(numerator / static_cast<Unsigned>(2 * (c - top_site)));
        if (start >= hi) continue;
      }
      ++top;
      top_site = c;
      top_start = start;
      top_value = value;
      site[top] = c;
      site_start[top] = start;
      site_value[top] = static_cast<std::int32_t>(value);
    }
    if (top < 0) {
      std::fill(out + begin, out + end, -1);
      return;
    }
    std::int32_t* owner = owner_.data();
    std::fill(owner + lo, owner + end, -1);
    for (int k = 0; k <= top && site_start[k] < end; ++k) owner[site_start[k]] = site[k];
    const std::int32_t* vertical_index = vertical_index_.data();
    std::int32_t current = -1;
    for (int x = lo; x < begin; ++x) current = std::max(current, owner[x]);
    for (int x = begin; x < end; ++x) {
      current = std::max(current, owner[x]);
      const Int dx = x - current;
      out[x] =
          indexWithinReach(vertical_index[current], dx * dx + squared[current] <= reach_squared);
    }
  }

  const std::vector<std::int32_t>& column_;
  const std::vector<std::int32_t>& row_start_;
  const int width_;
  const int height_;
  const int reach_;
  const int blocks_;
  const bool window_enabled_;
  const int max_passes_;
  // Per column: the nearest edge pixel at or above the current row, and at or below it.
  std::vector<std::int32_t> up_row_;
  std::vector<std::int32_t> up_index_;
  std::vector<std::int32_t> down_row_;
  std::vector<std::int32_t> down_index_;
  // Per edge pixel: the next edge pixel down its column (-1 if none) and that one's row.
  std::vector<std::int32_t> next_in_column_;
  std::vector<std::int32_t> next_row_;
  // Per column of the current row: squared distance to the column's nearest edge pixel (clamped
  // to (R + 1)^2) and its index; the squares again in int16 for the window search, padded with
  // (R + 1)^2 by kMaxPasses on the left and to whole blocks plus kMaxPasses on the right.
  std::vector<std::int32_t> squared_;
  std::vector<std::int32_t> vertical_index_;
  std::vector<std::int16_t> window_squared_;
  std::vector<std::uint8_t> window_easy_;  // Per block: the window search worked last time.
  // Per block: the smallest column distance^2 (clamped to (R + 1)^2) in it, and in the blocks
  // within R of it, a lower bound over every site that can matter to the block.
  std::vector<std::int32_t> block_floor_;
  std::vector<std::int32_t> near_floor_;
  // The lower envelope: site columns, the first column each wins and its g^2; then each
  // column's site.
  std::vector<std::int32_t> site_;
  std::vector<std::int32_t> site_start_;
  std::vector<std::int32_t> site_value_;
  std::vector<std::int32_t> owner_;
  std::vector<std::int32_t> row_out_;  // The row being swept.
};

}  // namespace

void NearestEdgeFieldOptions::validate() const {
  const OptionCheck require("NearestEdgeFieldOptions");
  require(max_distance_px >= 1 && max_distance_px <= 1000, "max_distance_px", max_distance_px,
          "in [1, 1000]");
}

NearestEdgeField NearestEdgeField::build(const cv::Mat& edges, const cv::Mat& grad_x,
                                         const cv::Mat& grad_y,
                                         const NearestEdgeFieldOptions& options) {
  options.validate();
  CURVESFM_CHECK(edges.type() == CV_8UC1) << "edges must be CV_8UC1, got type " << edges.type();
  CURVESFM_CHECK(grad_x.type() == grad_y.type())
      << "grad_x and grad_y must have the same type, got " << grad_x.type() << " and "
      << grad_y.type();
  CURVESFM_CHECK(grad_x.type() == CV_16SC1 || grad_x.type() == CV_32FC1)
      << "gradients must be CV_16SC1 or CV_32FC1, got type " << grad_x.type();
  CURVESFM_CHECK(grad_x.size() == edges.size() && grad_y.size() == edges.size())
      << "edges " << edges.size() << ", grad_x " << grad_x.size() << " and grad_y " << grad_y.size()
      << " must have the same size";

  NearestEdgeField field;
  field.width_ = edges.cols;
  field.height_ = edges.rows;
  field.max_distance_px_ = options.max_distance_px;
  const EdgeLayout layout = grad_x.type() == CV_16SC1
                                ? collectEdges<std::int16_t>(edges, grad_x, grad_y, &field.edges_)
                                : collectEdges<float>(edges, grad_x, grad_y, &field.edges_);
  const std::size_t pixels = static_cast<std::size_t>(field.width_) * field.height_;
  const std::size_t width = static_cast<std::size_t>(field.width_);
  DistanceSweep sweep(layout, field.width_, field.height_, options.max_distance_px);
  if (field.edges_.size() < kNoNarrowIndex) {
    field.narrow_index_.resize(pixels);
    sweep.run([&](int row, const std::int32_t* values) {
      std::transform(values, values + width, field.narrow_index_.data() + row * width,
                     [](std::int32_t index) {
                       return index < 0 ? kNoNarrowIndex : static_cast<std::uint16_t>(index);
                     });
    });
  } else {
    field.wide_index_.resize(pixels);
    sweep.run([&](int row, const std::int32_t* values) {
      std::copy(values, values + width, field.wide_index_.data() + row * width);
    });
  }
  return field;
}

}  // namespace curvesfm
