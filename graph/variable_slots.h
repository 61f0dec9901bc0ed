#pragma once

#include <functional>
#include <vector>

#include "graph/factor_graph.h"
#include "graph/key.h"
#include "graph/optimizer.h"
#include "graph/values.h"

namespace curvesfm {

// The variables a graph's factors use, laid out once for our own minimisers
// (graph/component_solver.h, graph/schur_solver.h).

/// A variable some factor uses, with its place in VariableSlots::ambient.
struct VariableSlot {
  Key key;
  VariableType type = VariableType::kScalar;
  int ambient = 0;  ///< Offset of its value in VariableSlots::ambient.
  bool free = false;
};

struct VariableSlots {
  std::vector<VariableSlot> slots;             ///< In the order factors first use them.
  std::vector<double> ambient;                 ///< Their start values, ambient coordinates.
  std::vector<std::vector<int>> factor_slots;  ///< Per graph factor, its keys' slots.
};

/// Every variable the factors of `graph` use, free unless `config` holds it. Throws
/// IncorrectType for a factor key whose value has another type than the factor expects.
VariableSlots collectVariableSlots(const FactorGraph& graph, const Values& values,
                                   const ProblemConfig& config);

/// The slots `member` selects, joined into sets by the factors they share: each member's set,
/// numbered in slot order from 0, and -1 for the other slots. `num_sets` gets the count.
std::vector<int> connectedSets(const VariableSlots& variables,
                               const std::function<bool(int slot)>& member, int* num_sets);

}  // namespace curvesfm
