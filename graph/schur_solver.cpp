#include "graph/schur_solver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iomanip>
#include <map>
#include <sstream>

#include "core/clock.h"
#include "core/dense_kernels.h"
#include "core/parallel.h"
#include "core/parallel_cholesky.h"
#include "graph/levenberg_marquardt.h"
#include "graph/variable_slots.h"

namespace curvesfm {
namespace {

constexpr int kPoseDim = 6;
using PoseBlock = Eigen::Matrix<double, kPoseDim, kPoseDim>;
using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A variable some factor uses.
struct Slot {
  Key key;
  VariableType type = VariableType::kScalar;
  int ambient = 0;  // Offset in the ambient buffer of all slots.
  int dim = 0;      // Tangent dimension.
  int pose = -1;    // Free pose: its index in the reduced system.
  int group = -1;   // Free structure: its group ...
  int offset = 0;   // ... and its first tangent column in the group.
};

// A free key of a factor: where its Jacobian block goes.
struct FreeKey {
  int key = 0;  // Position in the factor's keys.
  int slot = 0;
  int local_pose = 0;  // Poses of a group's factor: its row block in Group::W.
};

struct FactorPlan {
  int group = -1;  // The structure group it touches; -1 for none.
  std::vector<FreeKey> free;
  int free_columns = 0;
  // Where its J_a^T J_b goes for each pair of free poses a >= b: J's columns of a and b, and
  // the pose pair's index.
  struct PoseTerm {
    int column_a = 0;
    int column_b = 0;
    int pair = 0;
  };
  std::vector<PoseTerm> pose_terms;
};

// Two free poses some factor joins, first >= second: a 6 x 6 lower block of the reduced system.
struct PosePair {
  int first = 0;
  int second = 0;
};

// Consecutive free poses, first to first + count - 1, whose row blocks of a group's W start at
// row block `local`.
struct PoseRun {
  int first = 0;
  int count = 0;
  int local = 0;
};

// A run may take in up to this many poses a group does not see (zero rows of W), so that its
// share of the reduced system goes in as a few large products rather than many small ones.
constexpr int kMaxPoseGap = 2;

// Structure variables joined by factors, eliminated together, and what one elimination leaves
// of them.
struct Group {
  std::vector<int> factors;
  std::vector<PoseRun> runs;  // Covering the free poses its factors touch, ascending.
  int local_poses = 0;        // Poses the runs cover.
  int dim = 0;
  Eigen::MatrixXd L;                // The Cholesky factor of the damped H (lower triangle).
  Eigen::VectorXd u;                // L^-1 g.
  Eigen::VectorXd step;
  double cost = 0.0;
};

// What one linearisation leaves of a group.
struct GroupSystem {
  Eigen::MatrixXd H;  // Gauss-Newton block of the group (dim x dim, lower triangle) ...
  Eigen::VectorXd g;  // ... its gradient ...
  Eigen::MatrixXd W;  // ... and its coupling to its poses (6 local_poses x dim).
};

// The Gauss-Newton system at one point, and every factor's cost there.
struct Linearization {
  std::vector<GroupSystem> groups;
  std::vector<PoseBlock> pose_terms;  // Per pose pair, the sum of the workers' terms.
  Eigen::VectorXd g_poses;
  Eigen::VectorXd pose_diagonal;  // The diagonal of the pose-pose terms.
  std::vector<double> factor_costs;
};

// Where one column of a factor's Jacobian goes.
struct ColumnPlace {
  int structure = -1;  // Its column in the group's H, W and g; -1 for a pose column ...
  int w_row = 0;       // ... whose row in the group's W ...
  int pose_row = 0;    // ... and in the reduced system.
};

// One thread's scratch and its share of the reduced system.
struct Worker {
  std::vector<PoseBlock> pose_terms;  // Pose-pose terms of its factors, per pose pair.
  Eigen::VectorXd g_poses;
  // Its groups' share of - W A^-1 W^T (lower triangle; thread 0 writes into the reduced system
  // itself) ...
  Eigen::MatrixXd S;
  Eigen::VectorXd rhs;  // ... and of W A^-1 g.
  // Storage of W L^-T for the group being eliminated: scratch, since a group of a long track
  // holds a W as large as the rest of its state, and back-substitution can start from W again.
  // It only grows: a buffer sized per group would go back to the system for every large one.
  Eigen::VectorXd v_storage;
  bool eliminated = true;
  // One factor's evaluation.
  std::vector<const double*> ambient;
  std::vector<double*> jacobians;
  std::vector<double> jacobian_storage;
  std::vector<double> error;
  Eigen::MatrixXd J;
  Eigen::VectorXd r;
  Eigen::MatrixXd JtJ;
  Eigen::VectorXd Jtr;
  std::vector<ColumnPlace> places;  // Per column of J.
};

struct Timings {
  double linearize = 0.0;  // Every evaluation: trial steps are linearised as they are tried.
  double eliminate = 0.0;
  double reduced = 0.0;
  double back_substitute = 0.0;
};

// How a minimisation ended, and where its time went.
struct Outcome {
  std::map<std::string, FactorTypeCost> initial_cost_by_type;
  int iterations = 0;
  int rejected = 0;
  bool converged = false;
  std::string message = "Maximum number of iterations reached.";
  Timings timings;
};

class GraphSchurProblem {
 public:
  GraphSchurProblem(const FactorGraph& graph, const Values& values, const ProblemConfig& config)
      : graph_(graph) {
    collectSlots(values, config);
    if (has_free_intrinsic_) return;  // Refused: no groups to form.
    formGroups();
    planFactors();
  }

  bool hasFreeIntrinsic() const { return has_free_intrinsic_; }

  int numPoses() const { return num_poses_; }
  int reducedDimension() const { return kPoseDim * num_poses_; }
  int maxGroupDimension() const {
    int most = 0;
    for (const Group& group : groups_) most = std::max(most, group.dim);
    return most;
  }
  int numGroups() const { return static_cast<int>(groups_.size()); }
  int numFreeSlots() const { return num_free_; }
  int numConstantSlots() const { return static_cast<int>(slots_.size()) - num_free_; }
  int numEffectiveParameters() const {
    int total = reducedDimension();
    for (const Group& group : groups_) total += group.dim;
    return total;
  }
  const std::vector<double>& start() const { return variables_.ambient; }

  void prepare(int num_threads) {
    workers_.resize(num_threads);
    const int n = reducedDimension();
    S_.resize(n, n);
    for (std::size_t t = 0; t < workers_.size(); ++t) {
      workers_[t].g_poses.resize(n);
      if (t > 0) workers_[t].S.resize(n, n);
      workers_[t].rhs.resize(n);
    }
    splitGroups();
    // Factors with no free key add a constant, as in Ceres' reported costs.
    fixed_cost_ = 0.0;
    for (Linearization& linearization : linearizations_) {
      linearization.groups.resize(groups_.size());
      linearization.factor_costs.assign(graph_.size(), 0.0);
    }
    for (const int f : constant_factors_) {
      const double cost = evaluateFactor(variables_.ambient, f, nullptr, nullptr, &workers_[0]);
      for (Linearization& linearization : linearizations_) linearization.factor_costs[f] = cost;
      fixed_cost_ += cost;
    }
  }

  // Cost per factor type at the current linearisation, i.e. at the solution the solver holds:
  // what FactorGraph::costByType would give there, without evaluating every factor again.
  std::map<std::string, FactorTypeCost> costByTypeAtLinearization() const {
    return graph_.sumByType(current().factor_costs);
  }

  // Cost at x, and the Gauss-Newton system there (Triggs-corrected, as Ceres) in the spare
  // linearisation: the solve still reads the current one until adoptLinearization(). A trial
  // step is linearised as it is evaluated, so that a kept step, most of them, needs no second
  // pass over the factors (whose residuals take most of a linearisation's time); a rejected one
  // costs its Jacobians for nothing.
  double linearize(const std::vector<double>& x) {
    Linearization& into = spare();
    parallel([&](int t) {
      Worker& worker = workers_[t];
      worker.pose_terms.assign(pose_pairs_.size(), PoseBlock::Zero());
      worker.g_poses.setZero();
      for (int i = ranges_[t]; i < ranges_[t + 1]; ++i) {
        Group& group = groups_[i];
        GroupSystem& system = into.groups[i];
        system.H.setZero(group.dim, group.dim);
        system.g.setZero(group.dim);
        system.W.setZero(kPoseDim * group.local_poses, group.dim);
        group.cost = 0.0;
        for (const int f : group.factors)
          group.cost += evaluateFactor(x, f, &system, &into, &worker);
      }
    });
    // Factors over poses only (priors, relative poses): few, on this thread.
    double cost = fixed_cost_;
    for (const int f : pose_factors_) cost += evaluateFactor(x, f, nullptr, &into, &workers_[0]);
    for (const Group& group : groups_) cost += group.cost;
    sumPoseTerms(&into);
    return cost;
  }

  // The last linearisation becomes the one the solve reads.
  void adoptLinearization() { current_ = 1 - current_; }

  double gradientMaxNorm() const {
    const Linearization& at = current();
    double most = at.g_poses.size() ? at.g_poses.lpNorm<Eigen::Infinity>() : 0.0;
    for (std::size_t i = 0; i < groups_.size(); ++i) {
      if (groups_[i].dim) most = std::max(most, at.groups[i].g.lpNorm<Eigen::Infinity>());
    }
    return most;
  }

  // The damped Gauss-Newton step (H + damping D) x = -g, D Marquardt's clamped diagonal of H;
  // false when a Cholesky fails. Fills pose_step_ and every group's step and returns the model's
  // decrease, -(g.x + x.H.x / 2) = (-g.x + damping x.D.x) / 2.
  bool solve(double damping, double* model_decrease, Timings* timings) {
    auto start = Clock::now();
    parallel([&](int t) { eliminate(damping, t); });
    for (const Worker& worker : workers_) {
      if (!worker.eliminated) return false;
    }
    timings->eliminate += secondsSince(start);

    start = Clock::now();
    const Linearization& at = current();
    pose_step_ = -at.g_poses;
    if (pose_step_.size() > 0) {
      for (std::size_t t = 1; t < workers_.size(); ++t) {
        S_.triangularView<Eigen::Lower>() += workers_[t].S;
      }
      for (const Worker& worker : workers_) pose_step_ += worker.rhs;
      if (!parallelCholesky(S_, static_cast<int>(workers_.size()))) return false;
      choleskySolveInPlace(S_, &pose_step_);
    }
    timings->reduced += secondsSince(start);

    start = Clock::now();
    parallel([&](int t) {
      for (int i = ranges_[t]; i < ranges_[t + 1]; ++i) backSubstitute(i);
    });
    double gx = at.g_poses.dot(pose_step_);
    double xDx = pose_step_.dot(marquardtDiagonal(at.pose_diagonal).cwiseProduct(pose_step_));
    for (std::size_t i = 0; i < groups_.size(); ++i) {
      const Group& group = groups_[i];
      gx += at.groups[i].g.dot(group.step);
      xDx += group.step.dot(marquardtDiagonal(at.groups[i].H.diagonal()).cwiseProduct(group.step));
    }
    *model_decrease = 0.5 * (-gx + damping * xDx);
    timings->back_substitute += secondsSince(start);
    bool finite = pose_step_.allFinite();
    for (const Group& group : groups_) finite = finite && group.step.allFinite();
    return finite;
  }

  double stepNorm() const {
    double squared = pose_step_.squaredNorm();
    for (const Group& group : groups_) squared += group.step.squaredNorm();
    return std::sqrt(squared);
  }

  double freeAmbientNorm(const std::vector<double>& x) const {
    double squared = 0.0;
    for (const Slot& slot : slots_) {
      if (slot.pose < 0 && slot.group < 0) continue;
      for (int i = 0; i < ambientDim(slot.type); ++i)
        squared += x[slot.ambient + i] * x[slot.ambient + i];
    }
    return std::sqrt(squared);
  }

  void retract(const std::vector<double>& x, std::vector<double>* out) const {
    *out = x;
    for (const Slot& slot : slots_) {
      const double* delta = nullptr;
      if (slot.pose >= 0) delta = pose_step_.data() + kPoseDim * slot.pose;
      if (slot.group >= 0) delta = groups_[slot.group].step.data() + slot.offset;
      if (delta)
        retractAmbient(slot.type, x.data() + slot.ambient, delta, out->data() + slot.ambient);
    }
  }

  void writeBack(const std::vector<double>& x, Values* values) const {
    for (const Slot& slot : slots_) {
      if (slot.pose >= 0 || slot.group >= 0)
        values->setFromAmbient(slot.key, x.data() + slot.ambient);
    }
  }

 private:
  const Linearization& current() const { return linearizations_[current_]; }
  Linearization& spare() { return linearizations_[1 - current_]; }

  void collectSlots(const Values& values, const ProblemConfig& config) {
    variables_ = collectVariableSlots(graph_, values, config);
    plans_.resize(graph_.size());
    for (const VariableSlot& variable : variables_.slots) {
      Slot slot{variable.key, variable.type, variable.ambient, tangentDim(variable.type)};
      if (variable.free) {
        ++num_free_;
        // Poses by type, so that a pose always has kPoseDim columns; the rest is structure,
        // but for an intrinsic: the reduced system holds poses only, and as structure a
        // variable every observation shares would join all the structure into one group.
        if (slot.type == VariableType::kPose3) slot.pose = num_poses_++;
        if (categoryOf(variable.key) == VariableCategory::kIntrinsics) has_free_intrinsic_ = true;
      }
      slots_.push_back(slot);
    }
  }

  void formGroups() {
    const auto isStructure = [&](int s) { return variables_.slots[s].free && slots_[s].pose < 0; };
    int num_groups = 0;
    const std::vector<int> group_of = connectedSets(variables_, isStructure, &num_groups);
    groups_.resize(num_groups);
    for (std::size_t s = 0; s < slots_.size(); ++s) {
      Slot& slot = slots_[s];
      slot.group = group_of[s];
      if (slot.group < 0) continue;
      slot.offset = groups_[slot.group].dim;
      groups_[slot.group].dim += slot.dim;
    }
  }

  void planFactors() {
    std::map<std::pair<int, int>, int> pair_of;
    for (std::size_t f = 0; f < graph_.size(); ++f) {
      FactorPlan& plan = plans_[f];
      const std::vector<int>& keys = variables_.factor_slots[f];
      bool any_free = false;
      for (std::size_t k = 0; k < keys.size(); ++k) {
        const Slot& slot = slots_[keys[k]];
        if (slot.pose < 0 && slot.group < 0) continue;
        any_free = true;
        if (slot.group >= 0) plan.group = slot.group;
        plan.free.push_back({static_cast<int>(k), keys[k], 0});
        plan.free_columns += slot.dim;
      }
      if (!any_free) {
        constant_factors_.push_back(static_cast<int>(f));
      } else if (plan.group < 0) {
        pose_factors_.push_back(static_cast<int>(f));
      } else {
        groups_[plan.group].factors.push_back(static_cast<int>(f));
      }
      planPoseTerms(&plan, &pair_of);
    }
    for (Group& group : groups_) planPoseRuns(&group);
  }

  void planPoseRuns(Group* group) {
    std::vector<int> poses;
    for (const int f : group->factors) {
      for (const FreeKey& key : plans_[f].free) {
        if (slots_[key.slot].pose >= 0) poses.push_back(slots_[key.slot].pose);
      }
    }
    std::sort(poses.begin(), poses.end());
    std::vector<PoseRun>& runs = group->runs;
    for (const int pose : poses) {
      if (!runs.empty() && pose - (runs.back().first + runs.back().count) <= kMaxPoseGap) {
        runs.back().count = pose - runs.back().first + 1;
      } else {
        runs.push_back({pose, 1, group->local_poses});
      }
      group->local_poses = runs.back().local + runs.back().count;
    }
    for (const int f : group->factors) {
      for (FreeKey& key : plans_[f].free) {
        const int pose = slots_[key.slot].pose;
        if (pose < 0) continue;
        const auto run = std::prev(std::upper_bound(
            runs.begin(), runs.end(), pose, [](int p, const PoseRun& r) { return p < r.first; }));
        key.local_pose = run->local + pose - run->first;
      }
    }
  }

  void planPoseTerms(FactorPlan* plan, std::map<std::pair<int, int>, int>* pair_of) {
    int column_a = 0;
    for (const FreeKey& a : plan->free) {
      const int pose_a = slots_[a.slot].pose;
      int column_b = 0;
      for (const FreeKey& b : plan->free) {
        const int pose_b = slots_[b.slot].pose;
        if (pose_a >= 0 && pose_b >= 0 && pose_a >= pose_b) {
          const auto [it, added] = pair_of->emplace(std::make_pair(pose_a, pose_b),
                                                    static_cast<int>(pose_pairs_.size()));
          if (added) pose_pairs_.push_back({pose_a, pose_b});
          plan->pose_terms.push_back({column_a, column_b, it->second});
        }
        column_b += slots_[b.slot].dim;
      }
      column_a += slots_[a.slot].dim;
    }
  }

  // Threads take contiguous runs of groups of about equal factor counts, always the same for a
  // given graph and thread count.
  void splitGroups() {
    const int num_threads = static_cast<int>(workers_.size());
    std::size_t total = 0;
    for (const Group& group : groups_) total += group.factors.size() + 1;
    ranges_.assign(1, 0);
    std::size_t done = 0;
    for (int i = 0; i < numGroups(); ++i) {
      done += groups_[i].factors.size() + 1;
      if (static_cast<int>(ranges_.size()) < num_threads &&
          done * num_threads >= total * ranges_.size()) {
        ranges_.push_back(i + 1);
      }
    }
    while (static_cast<int>(ranges_.size()) <= num_threads) ranges_.push_back(numGroups());
  }

  void parallel(const std::function<void(int)>& work) const {
    runInParallel(static_cast<int>(workers_.size()), work);
  }

  void sumPoseTerms(Linearization* into) const {
    into->g_poses = workers_[0].g_poses;
    into->pose_terms = workers_[0].pose_terms;
    for (std::size_t t = 1; t < workers_.size(); ++t) {
      into->g_poses += workers_[t].g_poses;
      for (std::size_t i = 0; i < into->pose_terms.size(); ++i)
        into->pose_terms[i] += workers_[t].pose_terms[i];
    }
    into->pose_diagonal.setZero(reducedDimension());
    for (std::size_t i = 0; i < pose_pairs_.size(); ++i) {
      const PosePair& pair = pose_pairs_[i];
      if (pair.first == pair.second) {
        into->pose_diagonal.segment<kPoseDim>(kPoseDim * pair.first) =
            into->pose_terms[i].diagonal();
      }
    }
  }

  // The factor's cost at x; with `into`, also its share of the system there (its group's in
  // `system`).
  double evaluateFactor(const std::vector<double>& x, int f, GroupSystem* system,
                        Linearization* into, Worker* worker) const {
    const bool linearize = into != nullptr;
    const Factor& factor = *graph_[f];
    const FactorPlan& plan = plans_[f];
    const std::vector<int>& keys = variables_.factor_slots[f];
    const int rows = factor.residualDimension();
    worker->ambient.resize(keys.size());
    worker->jacobians.assign(keys.size(), nullptr);
    for (std::size_t k = 0; k < keys.size(); ++k) {
      worker->ambient[k] = x.data() + slots_[keys[k]].ambient;
    }
    if (linearize) {
      worker->jacobian_storage.resize(static_cast<std::size_t>(rows) * plan.free_columns);
      int column = 0;
      for (const FreeKey& key : plan.free) {
        worker->jacobians[key.key] = worker->jacobian_storage.data() + std::size_t(rows) * column;
        column += slots_[key.slot].dim;
      }
    }
    worker->error.resize(rows);
    factor.evaluateRaw(worker->ambient.data(), worker->error.data(), worker->jacobians.data());
    const NoiseModel& noise = factor.noiseModel();
    const double s = Eigen::Map<const Eigen::VectorXd>(worker->error.data(), rows).squaredNorm() /
                     (noise.sigma * noise.sigma);
    double rho[3];
    noise.kernel.evaluate(s, rho);
    if (linearize) {
      accumulate(plan, rows, noise.sigma, s, rho, system, worker);
      into->factor_costs[f] = 0.5 * rho[0];
    }
    return 0.5 * rho[0];
  }

  // Adds the factor's corrected J^T J and J^T r to its group's system (H's lower triangle, W,
  // g) and to the worker's pose terms.
  void accumulate(const FactorPlan& plan, int rows, double sigma, double s, const double rho[3],
                  GroupSystem* group, Worker* worker) const {
    Eigen::MatrixXd& J = worker->J;
    J.resize(rows, plan.free_columns);
    std::vector<ColumnPlace>& places = worker->places;
    places.clear();
    for (const FreeKey& key : plan.free) {
      const Slot& slot = slots_[key.slot];
      J.middleCols(places.size(), slot.dim) =
          Eigen::Map<const RowMajorMatrix>(worker->jacobians[key.key], rows, slot.dim);
      for (int i = 0; i < slot.dim; ++i) {
        places.push_back(slot.pose >= 0 ? ColumnPlace{-1, kPoseDim * key.local_pose + i,
                                                      kPoseDim * slot.pose + i}
                                        : ColumnPlace{slot.offset + i, 0, 0});
      }
    }
    worker->r = Eigen::Map<const Eigen::VectorXd>(worker->error.data(), rows);
    whitenAndCorrect(sigma, s, rho, &J, &worker->r);
    // A few dozen columns: lazy products skip the blocked GEMM's packing. J^T J's lower
    // triangle only, read as JtJ(max, min).
    Eigen::MatrixXd& JtJ = worker->JtJ;
    JtJ.resize(plan.free_columns, plan.free_columns);
    JtJ.triangularView<Eigen::Lower>() = J.transpose().lazyProduct(J);
    worker->Jtr.noalias() = J.transpose().lazyProduct(worker->r);
    // Column by column rather than block by block: the blocks are 1 to 6 wide, and a
    // dynamic-size block costs more to set up than to add.
    const int n = plan.free_columns;
    for (int c = 0; c < n; ++c) {
      const int column = places[c].structure;
      if (column < 0) {
        worker->g_poses[places[c].pose_row] += worker->Jtr[c];
        continue;
      }
      group->g[column] += worker->Jtr[c];
      for (int k = 0; k < n; ++k) {
        const ColumnPlace& place = places[k];
        const double value = k >= c ? JtJ(k, c) : JtJ(c, k);
        if (place.structure >= column) {
          group->H(place.structure, column) += value;
        } else if (place.structure < 0) {
          group->W(place.w_row, column) += value;
        }
      }
    }
    for (const FactorPlan::PoseTerm& term : plan.pose_terms) {
      const int a = term.column_a, b = term.column_b;
      PoseBlock& sum = worker->pose_terms[term.pair];
      if (a == b) {
        sum += PoseBlock(JtJ.block<kPoseDim, kPoseDim>(a, a).selfadjointView<Eigen::Lower>());
      } else if (a > b) {
        sum += JtJ.block<kPoseDim, kPoseDim>(a, b);
      } else {
        sum += JtJ.block<kPoseDim, kPoseDim>(b, a).transpose();
      }
    }
  }

  // Factors this thread's groups' damped blocks and adds their share of the reduced system.
  void eliminate(double damping, int thread) {
    Worker* worker = &workers_[thread];
    Eigen::MatrixXd& S = thread == 0 ? S_ : worker->S;
    S.triangularView<Eigen::Lower>().setZero();
    if (thread == 0) addPoseTerms(damping);
    worker->rhs.setZero();
    worker->eliminated = true;
    for (int i = ranges_[thread]; i < ranges_[thread + 1]; ++i) {
      Group& group = groups_[i];
      const GroupSystem& system = current().groups[i];
      group.L = system.H;
      group.L.diagonal() += marquardtDiagonal(system.H.diagonal()) * damping;
      const dense::MatrixSpan L = dense::blockSpan(group.L, 0, 0, group.dim, group.dim);
      if (!dense::factorLower(L)) {
        worker->eliminated = false;
        return;
      }
      if (worker->v_storage.size() < system.W.size()) worker->v_storage.resize(system.W.size());
      Eigen::Map<Eigen::MatrixXd> V(worker->v_storage.data(), system.W.rows(), system.W.cols());
      V = system.W;
      dense::solveLowerTransposedRight(L, dense::blockSpan(V, 0, 0, V.rows(), group.dim));
      group.u = system.g;
      group.L.triangularView<Eigen::Lower>().solveInPlace(group.u);
      subtractFromReducedSystem(group, V, &S, &worker->rhs);
    }
  }

  // S -= V V^T and rhs += V u, run by run, straight into their blocks (lower triangle).
  static void subtractFromReducedSystem(const Group& group, Eigen::Map<Eigen::MatrixXd>& V,
                                        Eigen::MatrixXd* S, Eigen::VectorXd* rhs) {
    const auto rowsOfV = [&](const PoseRun& run) {
      return dense::blockSpan(V, kPoseDim * run.local, 0, kPoseDim * run.count, group.dim);
    };
    const auto blockOfS = [&](const PoseRun& a, const PoseRun& b) {
      return dense::blockSpan(*S, kPoseDim * a.first, kPoseDim * b.first, kPoseDim * a.count,
                              kPoseDim * b.count);
    };
    for (std::size_t i = 0; i < group.runs.size(); ++i) {
      const PoseRun& a = group.runs[i];
      rhs->segment(kPoseDim * a.first, kPoseDim * a.count).noalias() +=
          V.middleRows(kPoseDim * a.local, kPoseDim * a.count) * group.u;
      dense::subtractGramLower(blockOfS(a, a), rowsOfV(a));
      for (std::size_t j = 0; j < i; ++j) {
        dense::subtractProductTransposed(blockOfS(a, group.runs[j]), rowsOfV(a),
                                         rowsOfV(group.runs[j]));
      }
    }
  }

  // The pose-pose terms and their damping, into the reduced system's lower triangle.
  void addPoseTerms(double damping) {
    const Linearization& at = current();
    for (std::size_t i = 0; i < pose_pairs_.size(); ++i) {
      const PosePair& pair = pose_pairs_[i];
      S_.block<kPoseDim, kPoseDim>(kPoseDim * pair.first, kPoseDim * pair.second) +=
          at.pose_terms[i];
    }
    S_.diagonal() += marquardtDiagonal(at.pose_diagonal) * damping;
  }

  // x_group = A^-1 (-g - W^T x_poses) = L^-T (-u - L^-1 W^T x_poses).
  void backSubstitute(int i) {
    Group* group = &groups_[i];
    Eigen::VectorXd poses(kPoseDim * group->local_poses);
    for (const PoseRun& run : group->runs) {
      poses.segment(kPoseDim * run.local, kPoseDim * run.count) =
          pose_step_.segment(kPoseDim * run.first, kPoseDim * run.count);
    }
    group->step = -group->u;
    if (poses.size()) {
      Eigen::VectorXd coupling = current().groups[i].W.transpose() * poses;
      group->L.triangularView<Eigen::Lower>().solveInPlace(coupling);
      group->step -= coupling;
    }
    group->L.triangularView<Eigen::Lower>().transpose().solveInPlace(group->step);
  }

  const FactorGraph& graph_;
  VariableSlots variables_;
  std::vector<Slot> slots_;  // Index-aligned with variables_.slots.
  std::vector<FactorPlan> plans_;
  std::vector<Group> groups_;
  std::vector<int> pose_factors_;
  std::vector<int> constant_factors_;
  double fixed_cost_ = 0.0;
  int num_poses_ = 0;
  int num_free_ = 0;
  bool has_free_intrinsic_ = false;
  // The solve reads linearizations_[current_]; a trial step is linearised into the other.
  std::array<Linearization, 2> linearizations_;
  int current_ = 0;
  std::vector<Worker> workers_;
  std::vector<int> ranges_;  // Thread t takes groups [ranges_[t], ranges_[t + 1]).
  std::vector<PosePair> pose_pairs_;
  Eigen::MatrixXd S_;  // The damped reduced system (lower triangle), then its Cholesky factor.
  Eigen::VectorXd pose_step_;
};

std::string timingReport(const Outcome& outcome) {
  // The labels of Ceres' FullReport, so the benches read both the same way.
  const Timings& timings = outcome.timings;
  const int iterations = outcome.iterations;
  const int rejected = outcome.rejected;
  std::ostringstream os;
  os << std::fixed << std::setprecision(6) << "graph_schur: " << iterations
     << " iterations (dense kernels: " << dense::kernelVariant() << ")\n"
     << "Successful steps " << iterations - rejected + 1 << " (the start counts as one)\n"
     << "Unsuccessful steps " << rejected << "\n"
     << "  Residual only evaluation 0 (each trial step is linearised)\n"
     << "  Jacobian & residual evaluation " << timings.linearize << "\n"
     << "  Linear solver " << timings.eliminate + timings.reduced + timings.back_substitute << "\n"
     << "    groups eliminated " << timings.eliminate << ", reduced system " << timings.reduced
     << ", back-substitution " << timings.back_substitute << "\n";
  return os.str();
}

// Levenberg-Marquardt from x, with Ceres' step acceptance and trust-region rules.
Outcome minimise(GraphSchurProblem* problem, std::vector<double>* x,
                 const OptimizerOptions& options) {
  const auto start = Clock::now();
  Outcome out;
  const auto timed = [](double* seconds, auto&& work) {
    const auto clock = Clock::now();
    const auto result = work();
    *seconds += secondsSince(clock);
    return result;
  };
  double cost = timed(&out.timings.linearize, [&] { return problem->linearize(*x); });
  problem->adoptLinearization();
  out.initial_cost_by_type = problem->costByTypeAtLinearization();
  if (options.on_iteration) options.on_iteration({0, cost, secondsSince(start), false});
  const auto stop = [&out](const char* why) {
    out.converged = true;
    out.message = why;
  };
  if (problem->gradientMaxNorm() <= options.gradient_tolerance) stop("Gradient tolerance reached.");
  TrustRegionRadius radius(options.initial_trust_region_radius);
  StallTest stall(options.stall_iterations, options.stall_tolerance, cost);
  std::vector<double> candidate;
  while (!out.converged && out.iterations < options.max_iterations) {
    ++out.iterations;
    double model_decrease = 0.0;
    const bool valid =
        problem->solve(radius.damping(), &model_decrease, &out.timings) && model_decrease > 0.0;
    // As Ceres, a step too short or changing the cost too little ends the solve, kept or not,
    // and that last iteration is neither counted nor reported.
    const double x_norm = problem->freeAmbientNorm(*x);
    if (valid && problem->stepNorm() <=
                     (x_norm + options.parameter_tolerance) * options.parameter_tolerance) {
      stop("Parameter tolerance reached.");
      --out.iterations;
      break;
    }
    double new_cost = cost;
    if (valid) {
      problem->retract(*x, &candidate);
      new_cost = timed(&out.timings.linearize, [&] { return problem->linearize(candidate); });
    }
    const double change = cost - new_cost;
    if (valid && std::abs(change) <= options.function_tolerance * cost) {
      stop("Function tolerance reached.");
      --out.iterations;
      break;
    }
    const bool kept =
        valid && std::isfinite(new_cost) && change > kMinRelativeDecrease * model_decrease;
    if (kept) {
      x->swap(candidate);
      problem->adoptLinearization();
      cost = new_cost;
      radius.accept(change / model_decrease);
      if (problem->gradientMaxNorm() <= options.gradient_tolerance) {
        stop("Gradient tolerance reached.");
      }
    } else {
      ++out.rejected;
      radius.reject();
      if (radius.collapsed()) stop("Trust region radius fell below its minimum.");
    }
    if (options.on_iteration) {  // Ceres' convention: a rejected step reports its cost too.
      options.on_iteration({out.iterations, kept ? cost : new_cost, secondsSince(start), kept});
    }
    if (!out.converged && stall.stalled(cost)) stop("Cost stalled.");
  }
  return out;
}

}  // namespace

std::optional<OptimizationSummary> optimizeWithGraphSchur(const FactorGraph& graph, Values* values,
                                                          const ProblemConfig& config,
                                                          const OptimizerOptions& options,
                                                          std::string* why_not) {
  if (options.use_inner_iterations || options.trust_region != TrustRegion::kLevenbergMarquardt) {
    *why_not = options.use_inner_iterations ? "inner iterations" : "the dogleg trust region";
    return std::nullopt;
  }
  const auto start = Clock::now();
  GraphSchurProblem problem(graph, *values, config);
  if (problem.hasFreeIntrinsic()) {
    *why_not = "a free camera intrinsic";
    return std::nullopt;
  }
  if (problem.reducedDimension() > kGraphSchurMaxReducedDimension) {
    *why_not = std::to_string(problem.numPoses()) + " free poses (at most " +
               std::to_string(kGraphSchurMaxReducedDimension / kPoseDim) + ")";
    return std::nullopt;
  }
  if (problem.maxGroupDimension() > kGraphSchurMaxGroupDimension) {
    *why_not = "a structure group of " + std::to_string(problem.maxGroupDimension()) +
               " dimensions (at most " + std::to_string(kGraphSchurMaxGroupDimension) + ")";
    return std::nullopt;
  }
  OptimizationSummary summary;
  summary.num_factors = static_cast<int>(graph.size());
  summary.num_free_variables = problem.numFreeSlots();
  summary.num_constant_variables = problem.numConstantSlots();
  summary.num_effective_parameters = problem.numEffectiveParameters();
  for (const auto& factor : graph) summary.num_residuals += factor->residualDimension();
  summary.num_curve_blocks = problem.numGroups();
  problem.prepare(std::max(1, std::min(options.num_threads, problem.numGroups())));
  summary.setup_seconds = secondsSince(start);

  const auto solve_start = Clock::now();
  std::vector<double> x = problem.start();
  const Outcome outcome = minimise(&problem, &x, options);
  summary.solve_seconds = secondsSince(solve_start);
  summary.minimizer_seconds = summary.solve_seconds;

  const auto writeback_start = Clock::now();
  problem.writeBack(x, values);
  // Every factor's cost at the start and at x came with the linearisations there (x is always
  // the last point linearised: a rejected step is not); evaluating them again before and after
  // the solve took about 8 % of a local BA (kitchen, perf).
  summary.initial_cost_by_type = outcome.initial_cost_by_type;
  summary.final_cost_by_type = problem.costByTypeAtLinearization();
  summary.writeback_seconds = secondsSince(writeback_start);
  summary.initial_cost = totalCost(summary.initial_cost_by_type);
  summary.final_cost = totalCost(summary.final_cost_by_type);
  summary.iterations = outcome.iterations;
  summary.usable = std::isfinite(summary.final_cost);
  summary.termination = outcome.converged ? "CONVERGENCE" : "NO_CONVERGENCE";
  summary.message = outcome.message;
  summary.linear_solver = "GRAPH_SCHUR";
  summary.ordering = "graph_schur (" + std::to_string(problem.numGroups()) +
                     " groups eliminated, " + std::to_string(problem.numPoses()) +
                     " poses reduced)";
  summary.full_report = timingReport(outcome);
  if (options.verbose) std::printf("%s", summary.full_report.c_str());
  summary.total_seconds = secondsSince(start);
  return summary;
}

}  // namespace curvesfm
