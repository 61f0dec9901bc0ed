#include "frontend/image/edge_chains.h"

#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {
namespace {

constexpr double kPi = 3.14159265358979323846;

// State bits of a pixel in the padded work image.
constexpr std::uint8_t kEdge = 1;
constexpr std::uint8_t kJunction = 2;
constexpr std::uint8_t kVisited = 4;

// The 8-neighbourhood in ring order N, NE, E, SE, S, SW, W, NW (x right, y down).
constexpr std::array<int, 8> kRingX = {0, 1, 1, 1, 0, -1, -1, -1};
constexpr std::array<int, 8> kRingY = {-1, -1, 0, 1, 1, 1, 0, -1};

// Number of connected groups among the ring positions selected by `members`, where two positions
// are connected if `adjacent(i, j)`; only groups containing a position of `counted` are counted.
template <class Adjacent>
int countGroups(unsigned members, unsigned counted, Adjacent adjacent) {
  std::array<int, 8> group{};
  for (int i = 0; i < 8; ++i) group[i] = i;
  auto root = [&](int i) {
    while (group[i] != i) i = group[i];
    return i;
  };
  for (int i = 0; i < 8; ++i) {
    for (int j = i + 1; j < 8; ++j) {
      if ((members >> i & 1u) && (members >> j & 1u) && adjacent(i, j)) group[root(j)] = root(i);
    }
  }
  int groups = 0;
  for (int i = 0; i < 8; ++i) {
    if (!(members >> i & 1u) || root(i) != i) continue;
    for (int j = 0; j < 8; ++j) {
      if ((counted >> j & 1u) && (members >> j & 1u) && root(j) == i) {
        ++groups;
        break;
      }
    }
  }
  return groups;
}

// A pixel with edge neighbours `code` (bit k = ring position k) is a simple point if its edge
// neighbours form one 8-connected group and the background around it one 4-connected group
// touching it (Rosenfeld): then removing it changes no connectivity. End points (fewer than two
// neighbours) are kept so that thinning never shortens a curve.
bool isRemovable(unsigned code) {
  if (std::bitset<8>(code).count() < 2) return false;
  auto chebyshev_adjacent = [](int i, int j) {
    return std::abs(kRingX[i] - kRingX[j]) <= 1 && std::abs(kRingY[i] - kRingY[j]) <= 1;
  };
  auto four_adjacent = [](int i, int j) {
    return std::abs(kRingX[i] - kRingX[j]) + std::abs(kRingY[i] - kRingY[j]) == 1;
  };
  constexpr unsigned kAll = 0xFFu;
  constexpr unsigned kFourNeighbours = 0x55u;  // N, E, S, W.
  return countGroups(code, kAll, chebyshev_adjacent) == 1 &&
         countGroups(~code & kAll, kFourNeighbours, four_adjacent) == 1;
}

const std::array<bool, 256>& removableTable() {
  static const std::array<bool, 256> table = [] {
    std::array<bool, 256> removable{};
    for (unsigned code = 0; code < 256; ++code) removable[code] = isRemovable(code);
    return removable;
  }();
  return table;
}

// The edge map copied into an image with a one-pixel empty border, so that neighbour look-ups
// need no bounds checks, and the list of its edge pixels (row-major indices into it).
class WorkImage {
 public:
  explicit WorkImage(const cv::Mat& edges)
      : stride_(edges.cols + 2), state_(static_cast<std::size_t>(stride_) * (edges.rows + 2), 0) {
    pixels_.reserve(static_cast<std::size_t>(cv::countNonZero(edges)));
    for (int k = 0; k < 8; ++k) offsets_[k] = kRingY[k] * stride_ + kRingX[k];
    for (int r = 0; r < edges.rows; ++r) collectRow(edges.ptr<std::uint8_t>(r), edges.cols, r);
  }

  // Bit k set if ring neighbour k is an edge pixel. Branch-free: this runs several times per
  // edge pixel and dominates the cost of thinning.
  unsigned edgeCode(int index) const {
    const std::uint8_t* centre = &state_[index];
    unsigned code = 0;
    for (int k = 0; k < 8; ++k) code |= static_cast<unsigned>(centre[offsets_[k]] & kEdge) << k;
    return code;
  }

  // Bit k set if ring neighbour k is a chain pixel (an edge pixel that is no junction).
  unsigned chainCode(int index) const {
    const std::uint8_t* centre = &state_[index];
    unsigned code = 0;
    for (int k = 0; k < 8; ++k) {
      code |= static_cast<unsigned>((centre[offsets_[k]] & (kEdge | kJunction)) == kEdge) << k;
    }
    return code;
  }

  // Removes simple points until none is left. Only the first pass visits every pixel; later
  // passes revisit the neighbours of what the previous pass removed (on Canny output the first
  // pass does nearly all the work).
  void thin() {
    const std::array<bool, 256>& removable = removableTable();
    std::vector<int> removed;
    std::vector<int> candidates = pixels_;
    while (!candidates.empty()) {
      removed.clear();
      for (const int index : candidates) {
        if (state_[index] == kEdge && removable[edgeCode(index)]) {
          state_[index] = 0;
          removed.push_back(index);
        }
      }
      candidates.clear();
      for (const int index : removed) {
        for (const int offset : offsets_) {
          if (state_[index + offset] == kEdge) candidates.push_back(index + offset);
        }
      }
    }
    pixels_.erase(std::remove_if(pixels_.begin(), pixels_.end(),
                                 [this](int index) { return state_[index] == 0; }),
                  pixels_.end());
  }

  void markJunctions() {
    for (const int index : pixels_) {
      if (std::bitset<8>(edgeCode(index)).count() >= 3) state_[index] |= kJunction;
    }
  }

  // An unvisited chain pixel (edge, not junction) next to `index`, or -1.
  int nextOnChain(int index) const {
    for (int k = 0; k < 8; ++k) {
      const int neighbour = index + offsets_[k];
      if (state_[neighbour] == kEdge) return neighbour;
    }
    return -1;
  }

  // True if `index` is an unvisited chain pixel with at most one chain pixel next to it.
  bool isChainEnd(int index) const {
    const unsigned code = chainCode(index);
    return state_[index] == kEdge && (code & (code - 1)) == 0;
  }

  bool isUnvisitedChainPixel(int index) const { return state_[index] == kEdge; }

  // Follows the chain from `start`, marking it visited, into `chain` (cleared first).
  void trace(int start, std::vector<int>* chain) {
    chain->clear();
    for (int index = start; index >= 0; index = nextOnChain(index)) {
      state_[index] |= kVisited;
      chain->push_back(index);
    }
  }

  const std::vector<int>& pixels() const { return pixels_; }
  Eigen::Vector2i pixelOf(int index) const {
    return Eigen::Vector2i(index % stride_ - 1, index / stride_ - 1);
  }

 private:
  // Marks the edge pixels of image row `r`. Edge maps are sparse (a few per cent), so eight
  // empty bytes at a time are skipped with one comparison.
  void collectRow(const std::uint8_t* row, int width, int r) {
    const int base = (r + 1) * stride_ + 1;
    int c = 0;
    for (; c + 8 <= width; c += 8) {
      std::uint64_t block;
      std::memcpy(&block, row + c, sizeof(block));
      if (block == 0) continue;
      for (int k = c; k < c + 8; ++k) mark(row[k], base + k);
    }
    for (; c < width; ++c) mark(row[c], base + c);
  }

  void mark(std::uint8_t value, int index) {
    if (value == 0) return;
    state_[index] = kEdge;
    pixels_.push_back(index);
  }

  int stride_;
  std::array<int, 8> offsets_{};
  std::vector<std::uint8_t> state_;
  std::vector<int> pixels_;
};

// Cosine of the turn at position i of `points` (see EdgeChainOptions), with the arms p[i - back]
// -> p[i] and p[i] -> p[i + ahead]; positions wrap around for a closed chain.
double turnCosine(const std::vector<Eigen::Vector2i>& points, int i, int back, int ahead) {
  const int n = static_cast<int>(points.size());
  const Eigen::Vector2i a = points[i] - points[(i - back + n) % n];
  const Eigen::Vector2i b = points[(i + ahead) % n] - points[i];
  const double norms = std::sqrt(static_cast<double>(a.squaredNorm()) * b.squaredNorm());
  return norms > 0.0 ? a.dot(b) / norms : 1.0;
}

// Positions of `points` where the chain turns by more than the limit: one per run of turning
// positions, at its sharpest turn. Open chains measure the turn only where both arms are at
// least half a window long (shorter arms near the ends are truncated to what is there); closed
// loops shorter than two windows are never split, nor loops that turn everywhere (small
// circles, which have no corner to cut at).
void findSplits(const std::vector<Eigen::Vector2i>& points, bool closed,
                const EdgeChainOptions& options, std::vector<int>* splits) {
  splits->clear();
  const int n = static_cast<int>(points.size());
  const int w = options.turn_window_px;
  const int min_arm = closed ? w : std::max(1, (w + 1) / 2);
  if (n < 2 * min_arm + 1) return;
  const double cos_limit = std::cos(options.max_turn_deg * kPi / 180.0);
  const int first = closed ? 0 : min_arm;
  const int last = closed ? n - 1 : n - 1 - min_arm;
  auto cosine = [&](int i) {
    return closed ? turnCosine(points, i, w, w)
                  : turnCosine(points, i, std::min(w, i), std::min(w, n - 1 - i));
  };
  // A closed loop is scanned from a position that does not turn, so that no run wraps around.
  int offset = 0;
  if (closed) {
    while (offset < n && cosine(offset) < cos_limit) ++offset;
    if (offset == n) return;
  }
  int best = -1;
  double best_cosine = cos_limit;
  for (int k = first; k <= last + 1; ++k) {
    const int i = (k + offset) % n;
    const double c = k <= last ? cosine(i) : 1.0;
    if (c < best_cosine) {
      best = i;
      best_cosine = c;
    } else if (c >= cos_limit && best >= 0) {
      splits->push_back(best);
      best = -1;
      best_cosine = cos_limit;
    }
  }
  std::sort(splits->begin(), splits->end());
}

EdgeChain makeChain(const std::vector<Eigen::Vector2i>& points, int begin, int count, bool closed,
                    const cv::Mat& grad_x, const cv::Mat& grad_y) {
  const int n = static_cast<int>(points.size());
  EdgeChain chain;
  chain.closed = closed;
  chain.pixels.reserve(count);
  chain.normals.reserve(count);
  double orientation = 0.0;
  for (int k = 0; k < count; ++k) {
    const Eigen::Vector2i& p = points[(begin + k) % n];
    const Eigen::Vector2f g(grad_x.at<std::int16_t>(p.y(), p.x()),
                            grad_y.at<std::int16_t>(p.y(), p.x()));
    const float norm = g.norm();
    chain.pixels.push_back(p);
    chain.normals.push_back(norm > 0.0f ? Eigen::Vector2f(g / norm) : Eigen::Vector2f(1.0f, 0.0f));
    if (k + 1 < count || closed) {
      const Eigen::Vector2f step = (points[(begin + k + 1) % n] - p).cast<float>();
      orientation += step.x() * chain.normals.back().y() - step.y() * chain.normals.back().x();
    }
  }
  if (orientation < 0.0) {
    std::reverse(chain.pixels.begin(), chain.pixels.end());
    std::reverse(chain.normals.begin(), chain.normals.end());
  }
  return chain;
}

// Cuts one traced chain at its sharp turns and appends the pieces that are long enough.
void emitPieces(const std::vector<Eigen::Vector2i>& points, bool closed,
                const std::vector<int>& splits, const EdgeChainOptions& options,
                const EdgeImage& edge_image, std::vector<EdgeChain>* chains) {
  const int n = static_cast<int>(points.size());
  auto emit = [&](int begin, int count, bool piece_closed) {
    if (count >= options.min_length_px) {
      chains->push_back(
          makeChain(points, begin, count, piece_closed, edge_image.grad_x, edge_image.grad_y));
    }
  };
  if (splits.empty()) {
    emit(0, n, closed);
    return;
  }
  // Each split position ends its piece; an open chain's last piece ends at its end point, a
  // loop's wraps around to the first split.
  int begin = closed ? splits.back() + 1 : 0;
  for (const int split : splits) {
    emit(begin % n, (split - begin + n) % n + 1, false);
    begin = split + 1;
  }
  if (!closed) emit(begin, n - begin, false);
}

}  // namespace

void EdgeChainOptions::validate() const {
  const OptionCheck require("EdgeChainOptions");
  require(min_length_px >= 2 && min_length_px <= 1000000, "min_length_px", min_length_px,
          "in [2, 1e6]");
  require(max_turn_deg > 0.0 && max_turn_deg <= 180.0, "max_turn_deg", max_turn_deg, "in (0, 180]");
  require(turn_window_px >= 1 && turn_window_px <= 1000, "turn_window_px", turn_window_px,
          "in [1, 1000]");
}

double EdgeChain::arcLength() const {
  double length = 0.0;
  for (std::size_t i = 1; i < pixels.size(); ++i) {
    length += (pixels[i] - pixels[i - 1]).cast<double>().norm();
  }
  if (closed && pixels.size() > 1) length += (pixels.front() - pixels.back()).cast<double>().norm();
  return length;
}

std::vector<EdgeChain> extractEdgeChains(const EdgeImage& edge_image,
                                         const EdgeChainOptions& options) {
  options.validate();
  const cv::Mat& edges = edge_image.edges;
  CURVESFM_CHECK(edges.type() == CV_8UC1) << "edges must be CV_8UC1, got type " << edges.type();
  CURVESFM_CHECK(edge_image.grad_x.type() == CV_16SC1 && edge_image.grad_y.type() == CV_16SC1)
      << "gradients must be CV_16SC1, got types " << edge_image.grad_x.type() << " and "
      << edge_image.grad_y.type();
  CURVESFM_CHECK(edge_image.grad_x.size() == edges.size() &&
                 edge_image.grad_y.size() == edges.size())
      << "edges " << edges.size() << ", grad_x " << edge_image.grad_x.size() << " and grad_y "
      << edge_image.grad_y.size() << " must have the same size";

  WorkImage work(edges);
  work.thin();
  work.markJunctions();

  std::vector<EdgeChain> chains;
  std::vector<int> traced;
  std::vector<Eigen::Vector2i> points;
  std::vector<int> splits;
  traced.reserve(work.pixels().size());
  points.reserve(work.pixels().size());
  auto process = [&](int start, bool closed) {
    work.trace(start, &traced);
    points.clear();
    for (const int index : traced) points.push_back(work.pixelOf(index));
    findSplits(points, closed, options, &splits);
    emitPieces(points, closed, splits, options, edge_image, &chains);
  };
  // Open chains first, from their end points; whatever is left are closed loops.
  for (const int index : work.pixels()) {
    if (work.isChainEnd(index)) process(index, false);
  }
  for (const int index : work.pixels()) {
    if (work.isUnvisitedChainPixel(index)) process(index, true);
  }
  return chains;
}

cv::Mat chainEdgeMap(const std::vector<EdgeChain>& chains, const cv::Size& size) {
  cv::Mat edges(size, CV_8UC1, cv::Scalar(0));
  for (const EdgeChain& chain : chains) {
    for (const Eigen::Vector2i& p : chain.pixels) {
      CURVESFM_CHECK(p.x() >= 0 && p.y() >= 0 && p.x() < size.width && p.y() < size.height)
          << "chain pixel (" << p.x() << ", " << p.y() << ") outside the image " << size;
      edges.at<std::uint8_t>(p.y(), p.x()) = 255;
    }
  }
  return edges;
}

}  // namespace curvesfm
