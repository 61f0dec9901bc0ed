#include "factors/curve_precision.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include "core/check.h"
#include "core/clock.h"
#include "core/median.h"
#include "factors/centre_precision.h"
#include "graph/variable_traits.h"

namespace curvesfm {
namespace {

constexpr double kMadToSigma = 1.4826;  // A Gaussian's std dev over its median absolute value.
constexpr double kMaxCorrelation = 0.95;

const CurveReprojectionFactor* asEdgeFactor(const Factor& factor) {
  return dynamic_cast<const CurveReprojectionFactor*>(&factor);
}

// Factors whose information counts: the edge observations, and the terms on the structure alone
// (segment lengths, tangents). Pose priors, the gauge and points stay out.
bool counts(const Factor& factor) {
  if (asEdgeFactor(factor) != nullptr) return true;
  return std::none_of(factor.keys().begin(), factor.keys().end(), [](Key key) {
    const VariableCategory category = categoryOf(key);
    return category == VariableCategory::kPose || category == VariableCategory::kPoint;
  });
}

bool isStructure(Key key) { return categoryOf(key) != VariableCategory::kPose; }

// Every edge factor's residuals, evaluated once for the noise and the correlation; a capped
// sample sits at the field's reach.
struct EdgeResiduals {
  std::vector<Eigen::VectorXd> errors;  // per edge factor
  std::vector<double> caps;             // its field's reach
  std::vector<double> absolute;         // |r| of every live sample
  int observations = 0;                 // edge factors with a live sample
};

bool isLive(double residual, double cap) { return std::abs(residual) < cap; }

EdgeResiduals collectResiduals(const FactorGraph& graph, const Values& values) {
  EdgeResiduals out;
  for (const auto& factor : graph) {
    const CurveReprojectionFactor* edge = asEdgeFactor(*factor);
    if (edge == nullptr) continue;
    out.errors.push_back(edge->unwhitenedError(values));
    out.caps.push_back(edge->cappedResidual());
    const Eigen::VectorXd& e = out.errors.back();
    bool any = false;
    for (int k = 0; k < e.size(); ++k) {
      if (!isLive(e(k), out.caps.back())) continue;
      out.absolute.push_back(std::abs(e(k)));
      any = true;
    }
    out.observations += any ? 1 : 0;
  }
  return out;
}

// Pooled lag-1 correlation of consecutive live samples within 3 sigmas.
double lagOneCorrelation(const EdgeResiduals& residuals, double sigma) {
  double products = 0.0, leads = 0.0, lags = 0.0;
  for (std::size_t f = 0; f < residuals.errors.size(); ++f) {
    const Eigen::VectorXd& e = residuals.errors[f];
    const double cap = std::min(residuals.caps[f], 3.0 * sigma);
    for (int k = 1; k < e.size(); ++k) {
      if (!isLive(e(k - 1), cap) || !isLive(e(k), cap)) continue;
      products += e(k - 1) * e(k);
      leads += e(k - 1) * e(k - 1);
      lags += e(k) * e(k);
    }
  }
  if (leads <= 0.0 || lags <= 0.0) return 0.0;
  return std::clamp(products / std::sqrt(leads * lags), -kMaxCorrelation, kMaxCorrelation);
}

// Union-find over the structure keys that share a counted factor: a curve's Q, v and d.
class StructureGroups {
 public:
  int groupOf(Key key) { return find(indexOf(key)); }
  void join(Key a, Key b) { parent_[find(indexOf(a))] = find(indexOf(b)); }

 private:
  int indexOf(Key key) {
    const auto [it, added] = index_.emplace(key, static_cast<int>(parent_.size()));
    if (added) parent_.push_back(it->second);
    return it->second;
  }
  int find(int i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  std::unordered_map<Key, int> index_;
  std::vector<int> parent_;
};

// One group's normal equations: its structure block, its coupling to each pose it meets, and
// the poses' own blocks.
struct GroupSystem {
  std::map<Key, int> offset;  // structure key -> first tangent column
  int dimension = 0;
  Eigen::MatrixXd structure;
  std::map<int, Eigen::MatrixXd> coupling;  // pose -> dimension x 6
};

// Rows of one factor's Jacobian, already weighted, into the group's and the poses' blocks: only
// the blocks of the keys it touches, so that a long curve's factors cost no more than a short
// one's.
void accumulate(const Factor& factor, const std::vector<Eigen::MatrixXd>& rows, int pose,
                GroupSystem* group, Eigen::MatrixXd* reduced) {
  const std::vector<Key>& keys = factor.keys();
  const Eigen::MatrixXd* pose_rows = nullptr;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (!isStructure(keys[i])) pose_rows = &rows[i];
  }
  if (pose >= 0 && group->coupling[pose].size() == 0) {
    group->coupling[pose] = Eigen::MatrixXd::Zero(group->dimension, 6);
  }
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (!isStructure(keys[i])) continue;
    const int row = group->offset.at(keys[i]);
    for (std::size_t j = 0; j < keys.size(); ++j) {
      if (!isStructure(keys[j])) continue;
      group->structure.block(row, group->offset.at(keys[j]), rows[i].cols(), rows[j].cols())
          .noalias() += rows[i].transpose() * rows[j];
    }
    if (pose >= 0) {
      group->coupling[pose].middleRows(row, rows[i].cols()).noalias() +=
          rows[i].transpose() * *pose_rows;
    }
  }
  if (pose >= 0) {
    reduced->block<6, 6>(6 * pose, 6 * pose).noalias() += pose_rows->transpose() * *pose_rows;
  }
}

// The Jacobian rows of one factor linearised at `lin`, weighted by the robust kernel; an edge
// factor's live rows only, AR(1)-whitened along the samples when `correlation` != 0; a structure
// term's against the edges' sigma in the objective (`edge_model_sigma`), as the BA weighs them.
std::vector<Eigen::MatrixXd> weightedRows(const Factor& factor, const Linearization& lin,
                                          double edge_model_sigma, double correlation) {
  const NoiseModel& noise = factor.noiseModel();
  double rho[3];
  noise.kernel.evaluate(lin.error.squaredNorm() / (noise.sigma * noise.sigma), rho);
  const CurveReprojectionFactor* edge = asEdgeFactor(factor);
  const double weight =
      std::sqrt(std::max(rho[1], 0.0)) * (edge != nullptr ? 1.0 : edge_model_sigma / noise.sigma);
  const int n = static_cast<int>(lin.error.size());
  std::vector<bool> live(n, true);
  if (edge != nullptr) {
    for (int k = 0; k < n; ++k) live[k] = isLive(lin.error(k), edge->cappedResidual());
  }
  const double innovation = 1.0 / std::sqrt(1.0 - correlation * correlation);
  std::vector<Eigen::MatrixXd> rows;
  for (const Eigen::MatrixXd& j : lin.jacobians) {
    Eigen::MatrixXd whitened = j;
    for (int k = 0; k < n; ++k) {
      if (!live[k]) {
        whitened.row(k).setZero();
      } else if (edge != nullptr && correlation != 0.0 && k > 0 && live[k - 1]) {
        whitened.row(k) = (j.row(k) - correlation * j.row(k - 1)) * innovation;
      }
    }
    rows.push_back(whitened * weight);
  }
  return rows;
}

// Subtracts sum over pose pairs of coupling_b^T X_a from the poses' information, X_a the
// structure block's (pseudo-)inverse applied to coupling_a.
template <class Solve>
void subtractCouplings(const GroupSystem& group, const Solve& solve, Eigen::MatrixXd* reduced) {
  for (const auto& [a, coupling_a] : group.coupling) {
    const Eigen::MatrixXd solved = solve(coupling_a);
    for (const auto& [b, coupling_b] : group.coupling) {
      reduced->block<6, 6>(6 * b, 6 * a).noalias() -= coupling_b.transpose() * solved;
    }
  }
}

// Subtracts the group's part from the poses' information, its structure eliminated: by an LDLT
// where the structure block is well conditioned (a long curve's block has hundreds of rows, where
// an eigen-decomposition would cost most of the figure's time), else through the pseudo-inverse,
// so that a direction no observation fixes stays out.
void eliminate(const GroupSystem& group, Eigen::MatrixXd* reduced) {
  constexpr double kRelativeFloor = 1e-10;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(group.structure);
  const Eigen::VectorXd& pivots = ldlt.vectorD();
  if (ldlt.info() == Eigen::Success && pivots.minCoeff() > kRelativeFloor * pivots.maxCoeff()) {
    subtractCouplings(
        group, [&ldlt](const Eigen::MatrixXd& c) -> Eigen::MatrixXd { return ldlt.solve(c); },
        reduced);
    return;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(group.structure);
  const Eigen::VectorXd& lambda = eigen.eigenvalues();
  const double floor = kRelativeFloor * std::max(lambda.maxCoeff(), 0.0);
  const Eigen::VectorXd inverse =
      lambda.unaryExpr([floor](double l) { return l > floor ? 1.0 / l : 0.0; });
  const Eigen::MatrixXd& v = eigen.eigenvectors();
  subtractCouplings(
      group,
      [&](const Eigen::MatrixXd& c) -> Eigen::MatrixXd {
        return v * (inverse.asDiagonal() * (v.transpose() * c));
      },
      reduced);
}

// The pose information of one group's factors, the group eliminated, added to `reduced[i]` for
// each of `correlations`; each factor is linearised once for all of them.
void addGroup(const FactorGraph& graph, const std::vector<int>& factors, const Values& values,
              int keyframes, double edge_model_sigma, const std::vector<double>& correlations,
              std::vector<Eigen::MatrixXd>* reduced) {
  GroupSystem prototype;
  for (int f : factors) {
    for (Key key : graph[f]->keys()) {
      if (!isStructure(key) || prototype.offset.count(key) > 0) continue;
      prototype.offset[key] = prototype.dimension;
      prototype.dimension += tangentDim(values.type(key));
    }
  }
  prototype.structure = Eigen::MatrixXd::Zero(prototype.dimension, prototype.dimension);
  std::vector<GroupSystem> groups(correlations.size(), prototype);
  for (int f : factors) {
    const Factor& factor = *graph[f];
    int pose = -1;
    for (Key key : factor.keys()) {
      if (!isStructure(key)) pose = static_cast<int>(key.index());
    }
    if (pose >= keyframes) continue;
    const Linearization lin = factor.linearize(values);
    for (std::size_t c = 0; c < correlations.size(); ++c) {
      accumulate(factor, weightedRows(factor, lin, edge_model_sigma, correlations[c]), pose,
                 &groups[c], &(*reduced)[c]);
    }
  }
  for (std::size_t c = 0; c < correlations.size(); ++c) eliminate(groups[c], &(*reduced)[c]);
}

// The counted factors of each structure group, by factor index.
std::vector<std::vector<int>> groupFactors(const FactorGraph& graph) {
  StructureGroups groups;
  std::vector<int> counted;
  for (std::size_t f = 0; f < graph.size(); ++f) {
    const Factor& factor = *graph[f];
    if (!counts(factor)) continue;
    Key first;
    bool any = false;
    for (Key key : factor.keys()) {
      if (!isStructure(key)) continue;
      if (any) groups.join(key, first);
      first = key;
      any = true;
    }
    if (any) counted.push_back(static_cast<int>(f));
  }
  std::map<int, std::vector<int>> by_group;
  for (int f : counted) {
    for (Key key : graph[f]->keys()) {
      if (!isStructure(key)) continue;
      by_group[groups.groupOf(key)].push_back(f);
      break;
    }
  }
  std::vector<std::vector<int>> out;
  for (auto& [group, factors] : by_group) out.push_back(std::move(factors));
  return out;
}

// The edge factors' sigma in the objective, against which the structure terms weigh.
double edgeModelSigma(const FactorGraph& graph) {
  for (const auto& factor : graph) {
    if (asEdgeFactor(*factor) != nullptr) return factor->noiseModel().sigma;
  }
  return 1.0;
}

}  // namespace

namespace {

// The curves' information on the poses for each of `correlations` (curvePoseInformation).
std::vector<Eigen::MatrixXd> poseInformations(const CurveBundleAdjustmentProblem& problem,
                                              int keyframes, double pixel_sigma,
                                              const std::vector<double>& correlations) {
  CURVESFM_CHECK(keyframes >= 0 && pixel_sigma > 0.0)
      << keyframes << " keyframes, pixel sigma " << pixel_sigma;
  for (double correlation : correlations) {
    CURVESFM_CHECK(std::abs(correlation) < 1.0) << "correlation " << correlation;
  }
  const double model_sigma = edgeModelSigma(problem.graph);
  std::vector<Eigen::MatrixXd> reduced(correlations.size(),
                                       Eigen::MatrixXd::Zero(6 * keyframes, 6 * keyframes));
  for (const std::vector<int>& factors : groupFactors(problem.graph)) {
    addGroup(problem.graph, factors, problem.values, keyframes, model_sigma, correlations,
             &reduced);
  }
  for (Eigen::MatrixXd& information : reduced) information /= pixel_sigma * pixel_sigma;
  return reduced;
}

}  // namespace

Eigen::MatrixXd curvePoseInformation(const CurveBundleAdjustmentProblem& problem, int keyframes,
                                     double pixel_sigma, double correlation) {
  return poseInformations(problem, keyframes, pixel_sigma, {correlation}).front();
}

CurveCentrePrecision curveCentrePrecision(const CurveBundleAdjustmentProblem& problem,
                                          int keyframes) {
  CURVESFM_CHECK(keyframes >= 0) << keyframes << " keyframes";
  const Clock::time_point start = Clock::now();
  CurveCentrePrecision out;
  const EdgeResiduals residuals = collectResiduals(problem.graph, problem.values);
  out.observations = residuals.observations;
  out.samples = static_cast<int>(residuals.absolute.size());
  if (out.samples == 0) return out;
  out.pixel_sigma = kMadToSigma * upperMedian(residuals.absolute);
  if (!(out.pixel_sigma > 0.0)) return out;
  out.sample_correlation = lagOneCorrelation(residuals, out.pixel_sigma);
  const std::vector<Pose3> poses = extractPoses(problem.values, keyframes);
  const std::vector<Eigen::MatrixXd> information =
      poseInformations(problem, keyframes, out.pixel_sigma, {0.0, out.sample_correlation});
  out.predicted_centre_ate = predictedCentreAteFromInformation(information[0], poses);
  out.predicted_centre_ate_correlated = predictedCentreAteFromInformation(information[1], poses);
  out.seconds = secondsSince(start);
  return out;
}

}  // namespace curvesfm
