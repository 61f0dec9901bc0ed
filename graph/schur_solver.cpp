#include "graph/schur_solver.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iomanip>
#include <sstream>
#include <thread>

#include "core/clock.h"
#include "graph/levenberg_marquardt.h"
#include "graph/variable_slots.h"

namespace curvesfm {
namespace {

constexpr int kPoseDim = 6;
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
  int local_pose = 0;  // Poses of a group's factor: index in Group::poses.
};

struct FactorPlan {
  int group = -1;  // The structure group it touches; -1 for none.
  std::vector<FreeKey> free;
  int free_columns = 0;
};

// Structure variables joined by factors, eliminated together, and what one linearisation and
// one elimination leave of them.
struct Group {
  std::vector<int> factors;
  std::vector<int> poses;  // Free pose indices its factors touch, ascending.
  int dim = 0;
  Eigen::MatrixXd H;                // Gauss-Newton block of the group (dim x dim) ...
  Eigen::VectorXd g;                // ... its gradient ...
  Eigen::MatrixXd W;                // ... and its coupling to its poses (6 poses.size() x dim).
  Eigen::LLT<Eigen::MatrixXd> llt;  // Of the damped H.
  Eigen::MatrixXd V;                // L^-1 W^T.
  Eigen::VectorXd u;                // L^-1 g.
  Eigen::VectorXd step;
  double cost = 0.0;
};

// One thread's scratch and its share of the reduced system.
struct Worker {
  Eigen::MatrixXd H_poses;  // Pose-pose terms of its factors (lower blocks).
  Eigen::VectorXd g_poses;
  Eigen::MatrixXd S;      // Its groups' share of - W A^-1 W^T (lower blocks) ...
  Eigen::VectorXd rhs;    // ... and of W A^-1 g.
  std::vector<double> M;  // One group's V^T V; kept, since fresh pages of that size cost more.
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
};

struct Timings {
  double linearize = 0.0;
  double cost = 0.0;
  double eliminate = 0.0;
  double reduced = 0.0;
  double back_substitute = 0.0;
};

// How a minimisation ended, and where its time went.
struct Outcome {
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
    formGroups();
    planFactors();
  }

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
    for (Worker& worker : workers_) {
      worker.H_poses.resize(reducedDimension(), reducedDimension());
      worker.g_poses.resize(reducedDimension());
      worker.S.resize(reducedDimension(), reducedDimension());
      worker.rhs.resize(reducedDimension());
    }
    splitGroups();
    // Factors with no free key add a constant, as in Ceres' reported costs.
    fixed_cost_ = 0.0;
    for (const int f : constant_factors_) {
      fixed_cost_ += evaluateFactor(variables_.ambient, f, nullptr, false, &workers_[0]);
    }
  }

  // Cost at x; with `linearize`, also every group's H, g and W and the pose terms H_poses,
  // g_poses (Triggs-corrected Gauss-Newton, as Ceres).
  double evaluate(const std::vector<double>& x, bool linearize) {
    parallel([&](int t) {
      Worker& worker = workers_[t];
      if (linearize) {
        worker.H_poses.setZero();
        worker.g_poses.setZero();
      }
      for (int i = ranges_[t]; i < ranges_[t + 1]; ++i) {
        Group& group = groups_[i];
        if (linearize) {
          group.H.setZero(group.dim, group.dim);
          group.g.setZero(group.dim);
          group.W.setZero(kPoseDim * static_cast<int>(group.poses.size()), group.dim);
        }
        group.cost = 0.0;
        for (const int f : group.factors) {
          group.cost += evaluateFactor(x, f, linearize ? &group : nullptr, linearize, &worker);
        }
      }
    });
    // Factors over poses only (priors, relative poses): few, on this thread.
    double cost = fixed_cost_;
    for (const int f : pose_factors_)
      cost += evaluateFactor(x, f, nullptr, linearize, &workers_[0]);
    for (const Group& group : groups_) cost += group.cost;
    if (linearize) {
      H_poses_ = workers_[0].H_poses;
      g_poses_ = workers_[0].g_poses;
      for (std::size_t t = 1; t < workers_.size(); ++t) {
        H_poses_ += workers_[t].H_poses;
        g_poses_ += workers_[t].g_poses;
      }
    }
    return cost;
  }

  double gradientMaxNorm() const {
    double most = g_poses_.size() ? g_poses_.lpNorm<Eigen::Infinity>() : 0.0;
    for (const Group& group : groups_) {
      if (group.dim) most = std::max(most, group.g.lpNorm<Eigen::Infinity>());
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
    const int n = reducedDimension();
    pose_step_.resize(n);
    if (n > 0) {
      S_ = H_poses_;
      S_.diagonal() += marquardtDiagonal(H_poses_.diagonal()) * damping;
      Eigen::VectorXd rhs = -g_poses_;
      for (const Worker& worker : workers_) {
        S_ += worker.S;
        rhs += worker.rhs;
      }
      Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(S_);  // In place, from the lower triangle.
      if (llt.info() != Eigen::Success) return false;
      pose_step_ = llt.solve(rhs);
    }
    timings->reduced += secondsSince(start);

    start = Clock::now();
    parallel([&](int t) {
      for (int i = ranges_[t]; i < ranges_[t + 1]; ++i) backSubstitute(&groups_[i]);
    });
    double gx = g_poses_.dot(pose_step_);
    double xDx = pose_step_.dot(marquardtDiagonal(H_poses_.diagonal()).cwiseProduct(pose_step_));
    for (const Group& group : groups_) {
      gx += group.g.dot(group.step);
      xDx += group.step.dot(marquardtDiagonal(group.H.diagonal()).cwiseProduct(group.step));
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
  void collectSlots(const Values& values, const ProblemConfig& config) {
    variables_ = collectVariableSlots(graph_, values, config);
    plans_.resize(graph_.size());
    for (const VariableSlot& variable : variables_.slots) {
      Slot slot{variable.key, variable.type, variable.ambient, tangentDim(variable.type)};
      if (variable.free) {
        ++num_free_;
        // Poses by type, so that a pose always has kPoseDim columns; the rest is structure.
        if (slot.type == VariableType::kPose3) slot.pose = num_poses_++;
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
        Group& group = groups_[plan.group];
        group.factors.push_back(static_cast<int>(f));
        for (const FreeKey& key : plan.free) {
          if (slots_[key.slot].pose >= 0) group.poses.push_back(slots_[key.slot].pose);
        }
      }
    }
    for (Group& group : groups_) {
      std::sort(group.poses.begin(), group.poses.end());
      group.poses.erase(std::unique(group.poses.begin(), group.poses.end()), group.poses.end());
      for (const int f : group.factors) {
        for (FreeKey& key : plans_[f].free) {
          const int pose = slots_[key.slot].pose;
          if (pose < 0) continue;
          key.local_pose = static_cast<int>(
              std::lower_bound(group.poses.begin(), group.poses.end(), pose) - group.poses.begin());
        }
      }
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
    std::vector<std::thread> threads;
    for (std::size_t t = 1; t < workers_.size(); ++t)
      threads.emplace_back(work, static_cast<int>(t));
    work(0);
    for (std::thread& thread : threads) thread.join();
  }

  double evaluateFactor(const std::vector<double>& x, int f, Group* group, bool linearize,
                        Worker* worker) {
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
    if (linearize) accumulate(plan, rows, noise.sigma, s, rho, group, worker);
    return 0.5 * rho[0];
  }

  // Adds the factor's corrected J^T J and J^T r to its group (H, W, g) and to the worker's pose
  // terms.
  void accumulate(const FactorPlan& plan, int rows, double sigma, double s, const double rho[3],
                  Group* group, Worker* worker) const {
    Eigen::MatrixXd& J = worker->J;
    J.resize(rows, plan.free_columns);
    int column = 0;
    for (const FreeKey& key : plan.free) {
      const int dim = slots_[key.slot].dim;
      J.middleCols(column, dim) =
          Eigen::Map<const RowMajorMatrix>(worker->jacobians[key.key], rows, dim);
      column += dim;
    }
    worker->r = Eigen::Map<const Eigen::VectorXd>(worker->error.data(), rows);
    whitenAndCorrect(sigma, s, rho, &J, &worker->r);
    // A few dozen columns: lazy products skip the blocked GEMM's packing.
    worker->JtJ.noalias() = J.transpose().lazyProduct(J);
    worker->Jtr.noalias() = J.transpose().lazyProduct(worker->r);
    int ca = 0;
    for (const FreeKey& a : plan.free) {
      const Slot& sa = slots_[a.slot];
      if (sa.pose >= 0) {
        worker->g_poses.segment<kPoseDim>(kPoseDim * sa.pose) += worker->Jtr.segment<kPoseDim>(ca);
      } else {
        group->g.segment(sa.offset, sa.dim) += worker->Jtr.segment(ca, sa.dim);
      }
      int cb = 0;
      for (const FreeKey& b : plan.free) {
        const Slot& sb = slots_[b.slot];
        const auto block = worker->JtJ.block(ca, cb, sa.dim, sb.dim);
        if (sa.group >= 0 && sb.group >= 0) {
          group->H.block(sa.offset, sb.offset, sa.dim, sb.dim) += block;
        } else if (sa.pose >= 0 && sb.group >= 0) {
          group->W.block(kPoseDim * a.local_pose, sb.offset, kPoseDim, sb.dim) += block;
        } else if (sa.pose >= 0 && sb.pose >= 0 && sa.pose >= sb.pose) {  // Lower blocks.
          worker->H_poses.block<kPoseDim, kPoseDim>(kPoseDim * sa.pose, kPoseDim * sb.pose) +=
              block;
        }
        cb += sb.dim;
      }
      ca += sa.dim;
    }
  }

  // Factors this thread's groups' damped blocks and adds their share of the reduced system.
  void eliminate(double damping, int thread) {
    Worker* worker = &workers_[thread];
    worker->S.setZero();
    worker->rhs.setZero();
    worker->eliminated = true;
    for (int i = ranges_[thread]; i < ranges_[thread + 1]; ++i) {
      Group& group = groups_[i];
      Eigen::MatrixXd A = group.H;
      A.diagonal() += marquardtDiagonal(group.H.diagonal()) * damping;
      group.llt.compute(A);
      if (group.llt.info() != Eigen::Success) {
        worker->eliminated = false;
        return;
      }
      group.V = group.W.transpose();
      group.llt.matrixL().solveInPlace(group.V);
      group.u = group.g;
      group.llt.matrixL().solveInPlace(group.u);
      const int m = static_cast<int>(group.poses.size());
      if (m == 0) continue;
      worker->M.resize(
          std::max<std::size_t>(worker->M.size(), std::size_t(kPoseDim * m) * kPoseDim * m));
      Eigen::Map<Eigen::MatrixXd> M(worker->M.data(), kPoseDim * m, kPoseDim * m);
      M.setZero();
      M.selfadjointView<Eigen::Lower>().rankUpdate(group.V.transpose());
      const Eigen::VectorXd Vtu = group.V.transpose() * group.u;
      for (int a = 0; a < m; ++a) {
        const int pa = kPoseDim * group.poses[a];
        worker->rhs.segment<kPoseDim>(pa) += Vtu.segment<kPoseDim>(kPoseDim * a);
        for (int b = 0; b <= a; ++b) {
          worker->S.block<kPoseDim, kPoseDim>(pa, kPoseDim * group.poses[b]) -=
              M.block<kPoseDim, kPoseDim>(kPoseDim * a, kPoseDim * b);
        }
      }
    }
  }

  // x_group = A^-1 (-g - W^T x_poses) = L^-T (-u - V x_poses).
  void backSubstitute(Group* group) const {
    Eigen::VectorXd poses(kPoseDim * group->poses.size());
    for (std::size_t a = 0; a < group->poses.size(); ++a) {
      poses.segment<kPoseDim>(kPoseDim * a) =
          pose_step_.segment<kPoseDim>(kPoseDim * group->poses[a]);
    }
    group->step = -group->u;
    if (poses.size()) group->step.noalias() -= group->V * poses;
    group->llt.matrixU().solveInPlace(group->step);
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
  std::vector<Worker> workers_;
  std::vector<int> ranges_;  // Thread t takes groups [ranges_[t], ranges_[t + 1]).
  Eigen::MatrixXd H_poses_;
  Eigen::VectorXd g_poses_;
  Eigen::MatrixXd S_;
  Eigen::VectorXd pose_step_;
};

std::string timingReport(const Outcome& outcome) {
  // The labels of Ceres' FullReport, so the benches read both the same way.
  const Timings& timings = outcome.timings;
  const int iterations = outcome.iterations;
  const int rejected = outcome.rejected;
  std::ostringstream os;
  os << std::fixed << std::setprecision(6) << "graph_schur: " << iterations << " iterations\n"
     << "Successful steps " << iterations - rejected + 1 << " (the start counts as one)\n"
     << "Unsuccessful steps " << rejected << "\n"
     << "  Residual only evaluation " << timings.cost << "\n"
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
  double cost = timed(&out.timings.linearize, [&] { return problem->evaluate(*x, true); });
  if (options.on_iteration) options.on_iteration({0, cost, secondsSince(start), false});
  const auto stop = [&out](const char* why) {
    out.converged = true;
    out.message = why;
  };
  if (problem->gradientMaxNorm() <= options.gradient_tolerance) stop("Gradient tolerance reached.");
  TrustRegionRadius radius(options.initial_trust_region_radius);
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
      new_cost = timed(&out.timings.cost, [&] { return problem->evaluate(candidate, false); });
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
      cost = timed(&out.timings.linearize, [&] { return problem->evaluate(*x, true); });
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
  summary.initial_cost_by_type = graph.costByType(*values);
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
  summary.final_cost_by_type = graph.costByType(*values);
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
