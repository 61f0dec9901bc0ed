#include "graph/variable_slots.h"

#include <unordered_map>

#include "core/union_find.h"

namespace curvesfm {

VariableSlots collectVariableSlots(const FactorGraph& graph, const Values& values,
                                   const ProblemConfig& config) {
  VariableSlots variables;
  std::unordered_map<Key, int> slot_of;
  variables.factor_slots.resize(graph.size());
  for (std::size_t f = 0; f < graph.size(); ++f) {
    const std::vector<VariableType> types = graph[f]->variableTypes();
    for (std::size_t k = 0; k < types.size(); ++k) {
      const Key key = graph[f]->keys()[k];
      if (values.type(key) != types[k]) throw IncorrectType(key, values.type(key), types[k]);
      auto [it, added] = slot_of.emplace(key, static_cast<int>(variables.slots.size()));
      if (added) {
        VariableSlot slot{key, types[k], static_cast<int>(variables.ambient.size()),
                          !config.isConstant(key)};
        variables.ambient.resize(variables.ambient.size() + ambientDim(slot.type));
        values.toAmbient(key, variables.ambient.data() + slot.ambient);
        variables.slots.push_back(slot);
      }
      variables.factor_slots[f].push_back(it->second);
    }
  }
  return variables;
}

std::vector<int> connectedSets(const VariableSlots& variables,
                               const std::function<bool(int slot)>& member, int* num_sets) {
  const int n = static_cast<int>(variables.slots.size());
  UnionFind sets(n);
  for (const std::vector<int>& slots : variables.factor_slots) {
    int first = -1;
    for (const int s : slots) {
      if (!member(s)) continue;
      if (first < 0) first = s;
      sets.join(s, first);
    }
  }
  std::vector<int> set_of(n, -1);
  std::unordered_map<int, int> set_of_root;
  for (int s = 0; s < n; ++s) {
    if (!member(s)) continue;
    set_of[s] =
        set_of_root.emplace(sets.find(s), static_cast<int>(set_of_root.size())).first->second;
  }
  *num_sets = static_cast<int>(set_of_root.size());
  return set_of;
}

}  // namespace curvesfm
