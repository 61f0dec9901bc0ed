#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>
#include <deque>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli/cli_options.h"
#include "core/enum_names.h"

namespace curvesfm {

// The one road from an options struct to the user (COLMAP's option_manager in spirit): a table
// row per struct field gives its flag, which is also its config-file key, its heading in --help,
// and its place in report.json, so that the three cannot drift apart. A command builds its table
// from the struct tables of apps/cli/option_tables.h, registers the flags, validates through the
// table (errors then name the flag the user typed) and echoes table.toJson() in its report.

/// How many fields the aggregate `T` declares (nested structs count as one): it is
/// brace-initialisable from that many values that convert to anything, and not from one more.
/// The options table test compares it with the rows of each struct's table.
template <class T>
constexpr std::size_t aggregateFieldCount();

/// One field of an options struct.
struct OptionField {
  std::string field;  ///< As the struct spells it, e.g. "max_iterations".
  /// Long flag without dashes, also the config-file key; empty for a nested struct (its own
  /// group) or a field the command sets from another option (`note` says which).
  std::string flag;
  std::string note;
  /// Registers the flag on a command under a --help heading.
  std::function<CLI::Option*(CLI::App*, const std::string& heading)> add;
  std::function<nlohmann::json()> value;  ///< The value in force; empty for a nested struct.
  int* threads = nullptr;                 ///< A thread count that --threads sets.
};

/// The fields of one options struct instance.
struct OptionGroup {
  std::string struct_name;  ///< As its validate() names it, e.g. "SchedulerOptions".
  std::string path;         ///< JSON pointer below report.json's "options", e.g. "/pipeline/ba".
  std::string heading;      ///< Heading of its flags in --help.
  std::size_t struct_fields = 0;   ///< aggregateFieldCount of the struct.
  std::function<void()> validate;  ///< The struct's validate().
  std::vector<OptionField> fields;
};

/// Adds the rows of one group; returned by OptionsTable::group.
class OptionGroupBuilder {
 public:
  OptionGroupBuilder(OptionGroup* group, std::string flag_prefix)
      : group_(group), prefix_(std::move(flag_prefix)) {}

  /// `--<prefix><flag> VALUE` for an int, unsigned or double field.
  template <class T>
  OptionGroupBuilder& number(const std::string& field, const std::string& flag, T* target,
                             const std::string& description);
  /// `--<prefix><flag> BOOL` (true/false, yes/no, on/off, 1/0).
  OptionGroupBuilder& boolean(const std::string& field, const std::string& flag, bool* target,
                              const std::string& description);
  /// `--<prefix><flag> NAME` for an enum with EnumNames.
  template <class Enum>
  OptionGroupBuilder& enumeration(const std::string& field, const std::string& flag, Enum* target,
                                  const std::string& description);
  /// A value written as text, e.g. a vector "x,y,z": `parse` throws InvalidOptions for bad text.
  OptionGroupBuilder& text(const std::string& field, const std::string& flag,
                           const std::string& type_name, std::function<std::string()> print,
                           std::function<void(const std::string&)> parse,
                           const std::string& description);
  /// A thread count: a number that the command's --threads also sets.
  OptionGroupBuilder& threads(const std::string& field, const std::string& flag, int* target,
                              const std::string& description);
  /// A field without a flag that the command sets itself (`note` says from what); report.json
  /// shows `value()`, the value in force.
  OptionGroupBuilder& derived(const std::string& field, std::function<nlohmann::json()> value,
                              const std::string& note);
  /// A nested options struct: its fields are a group of their own.
  OptionGroupBuilder& nested(const std::string& field);

 private:
  OptionField& add(const std::string& field, const std::string& flag);

  OptionGroup* group_;
  std::string prefix_;
};

/// Every options struct a command exposes, as groups of rows.
class OptionsTable {
 public:
  /// Starts the group of `*options`: its rows go below `path` in report.json, its flags take
  /// `flag_prefix` and appear under `heading` in --help.
  template <class Options>
  OptionGroupBuilder group(Options* options, const std::string& struct_name,
                           const std::string& path, const std::string& flag_prefix,
                           const std::string& heading) {
    OptionGroup& group = groups_.emplace_back();
    group.struct_name = struct_name;
    group.path = path;
    group.heading = heading;
    group.struct_fields = aggregateFieldCount<Options>();
    group.validate = [options] { options->validate(); };
    return OptionGroupBuilder(&group, flag_prefix);
  }

  /// Registers every flag on `command`, and `--threads N` when some field counts threads and no
  /// field already owns that flag: it sets every thread count whose own flag was not given.
  void addFlags(CLI::App* command) const;
  /// Every field's value in force as nested JSON objects by path.
  nlohmann::json toJson() const;
  /// Validates every struct, nested ones first; an InvalidOptions whose field has a flag is
  /// rethrown worded for that flag (InvalidOptions::withFlag).
  void validate() const;
  const std::deque<OptionGroup>& groups() const { return groups_; }

 private:
  std::deque<OptionGroup> groups_;  // A deque: builders keep pointers into it.
};

// ---------------------------------------------------------------------------------------------
// Implementation of the templates.

namespace detail {
struct AnyField {
  template <class T>
  constexpr operator T() const;  // Never defined: only used in unevaluated contexts.
};
template <class T, class... Fields>
constexpr auto braceable(int) -> decltype(T{std::declval<Fields>()...}, true) {
  return true;
}
template <class T, class... Fields>
constexpr bool braceable(...) {
  return false;
}
template <class T, class... Fields>
constexpr std::size_t countFields() {
  if constexpr (braceable<T, Fields..., AnyField>(0)) {
    return countFields<T, Fields..., AnyField>();
  } else {
    return sizeof...(Fields);
  }
}
}  // namespace detail

template <class T>
constexpr std::size_t aggregateFieldCount() {
  static_assert(std::is_aggregate_v<T>, "options structs are plain aggregates");
  return detail::countFields<T>();
}

template <class T>
OptionGroupBuilder& OptionGroupBuilder::number(const std::string& field, const std::string& flag,
                                               T* target, const std::string& description) {
  OptionField& row = add(field, flag);
  const std::string name = "--" + row.flag;
  row.add = [name, target, description](CLI::App* command, const std::string& heading) {
    return command->add_option(name, *target, description)->capture_default_str()->group(heading);
  };
  row.value = [target] { return nlohmann::json(*target); };
  return *this;
}

template <class Enum>
OptionGroupBuilder& OptionGroupBuilder::enumeration(const std::string& field,
                                                    const std::string& flag, Enum* target,
                                                    const std::string& description) {
  OptionField& row = add(field, flag);
  const std::string name = row.flag;
  const std::string full = description + ": " + enumNameList<Enum>();
  row.add = [name, target, full](CLI::App* command, const std::string& heading) {
    return addEnumFlag(command, name, target, full)->group(heading);
  };
  row.value = [target] { return nlohmann::json(toString(*target)); };
  return *this;
}

}  // namespace curvesfm
