#pragma once

#include <array>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "core/errors.h"

namespace curvesfm {

// One way to name the values of an enum, for options, flags, config files and reports. An enum
// opts in with a specialisation beside its declaration:
//
//   template <>
//   struct EnumNames<Scope> {
//     static constexpr std::array<std::pair<Scope, const char*>, 2> kNames = {
//         {{Scope::kGlobal, "global"}, {Scope::kLocal, "local"}}};
//   };
//
// and gets toString(value), parseEnumName<Scope>(name, struct, field) and enumNameList<Scope>().

/// Specialise with `kNames`, an array of {value, name} pairs listing every value once.
template <class Enum>
struct EnumNames;

namespace detail {
template <class Enum, class = void>
struct HasEnumNames : std::false_type {};
template <class Enum>
struct HasEnumNames<Enum, std::void_t<decltype(EnumNames<Enum>::kNames)>> : std::true_type {};
}  // namespace detail

/// The name of `value`; "unknown" for a value outside the table (a cast from a bad integer).
template <class Enum, std::enable_if_t<detail::HasEnumNames<Enum>::value, int> = 0>
std::string toString(Enum value) {
  for (const auto& [entry, name] : EnumNames<Enum>::kNames) {
    if (entry == value) return name;
  }
  return "unknown";
}

/// Every name, in table order, comma separated: "global, local".
template <class Enum>
std::string enumNameList() {
  std::string list;
  for (const auto& entry : EnumNames<Enum>::kNames) {
    list += (list.empty() ? "" : ", ") + std::string(entry.second);
  }
  return list;
}

/// The value named `name`, or nothing for a name that is not in the table.
template <class Enum>
std::optional<Enum> findEnumName(const std::string& name) {
  for (const auto& [value, entry] : EnumNames<Enum>::kNames) {
    if (name == entry) return value;
  }
  return std::nullopt;
}

/// The value named `name`. Anything else throws InvalidOptions naming `struct_name`.`field`, the
/// name given and every accepted one: `InvalidOptions: SchedulerOptions.scope = "wide": expected
/// one of global, local`.
template <class Enum>
Enum parseEnumName(const std::string& name, const std::string& struct_name,
                   const std::string& field) {
  if (const std::optional<Enum> value = findEnumName<Enum>(name)) return *value;
  throw InvalidOptions(struct_name, field, "\"" + name + "\"",
                       "expected one of " + enumNameList<Enum>());
}

}  // namespace curvesfm
