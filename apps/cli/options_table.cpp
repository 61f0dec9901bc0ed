#include "apps/cli/options_table.h"

#include <algorithm>

#include "core/check.h"
#include "core/errors.h"

namespace curvesfm {

OptionField& OptionGroupBuilder::add(const std::string& field, const std::string& flag) {
  for (const OptionField& row : group_->fields) {
    CURVESFM_CHECK(row.field != field) << group_->struct_name << "." << field << " listed twice";
  }
  OptionField& row = group_->fields.emplace_back();
  row.field = field;
  if (!flag.empty()) row.flag = prefix_ + flag;
  return row;
}

OptionGroupBuilder& OptionGroupBuilder::boolean(const std::string& field, const std::string& flag,
                                                bool* target, const std::string& description) {
  OptionField& row = add(field, flag);
  const std::string name = row.flag;
  row.add = [name, target, description](CLI::App* command, const std::string& heading) {
    return addBoolFlag(command, name, target, description)->group(heading);
  };
  row.value = [target] { return nlohmann::json(*target); };
  return *this;
}

OptionGroupBuilder& OptionGroupBuilder::text(const std::string& field, const std::string& flag,
                                             const std::string& type_name,
                                             std::function<std::string()> print,
                                             std::function<void(const std::string&)> parse,
                                             const std::string& description) {
  OptionField& row = add(field, flag);
  const std::string name = "--" + row.flag;
  row.add = [=](CLI::App* command, const std::string& heading) {
    return command
        ->add_option_function<std::string>(name, parse, description)
        // Checked while parsing, so a bad value is a usage error naming the flag.
        ->check(CLI::Validator(
            [parse](std::string& value) -> std::string {
              try {
                parse(value);
              } catch (const InvalidOptions& e) {
                return e.what();
              }
              return "";
            },
            ""))
        ->type_name(type_name)
        ->default_str(print())
        ->group(heading);
  };
  row.value = [print] { return nlohmann::json(print()); };
  return *this;
}

OptionGroupBuilder& OptionGroupBuilder::threads(const std::string& field, const std::string& flag,
                                                int* target, const std::string& description) {
  number(field, flag, target, description);
  group_->fields.back().threads = target;
  return *this;
}

OptionGroupBuilder& OptionGroupBuilder::derived(const std::string& field,
                                                std::function<nlohmann::json()> value,
                                                const std::string& note) {
  OptionField& row = add(field, "");
  row.note = note;
  row.value = std::move(value);
  return *this;
}

OptionGroupBuilder& OptionGroupBuilder::nested(const std::string& field) {
  add(field, "");
  return *this;
}

void OptionsTable::addFlags(CLI::App* command) const {
  std::vector<std::pair<CLI::Option*, int*>> thread_counts;
  bool threads_taken = false;
  for (const OptionGroup& group : groups_) {
    for (const OptionField& row : group.fields) {
      if (!row.add) continue;
      CLI::Option* option = row.add(command, group.heading);
      if (row.threads) thread_counts.emplace_back(option, row.threads);
      threads_taken = threads_taken || row.flag == "threads";
    }
  }
  if (thread_counts.empty() || threads_taken) return;
  // Defined last, so CLI11 runs its callback after the stages' own flags have been stored.
  command
      ->add_option_function<int>(
          "--threads",
          [thread_counts](int threads) {
            if (threads == 0) return;  // The default: every stage keeps its own.
            for (const auto& [option, count] : thread_counts) {
              // A stage's own flag wins over the global one, wherever it was given.
              if (option->count() > 0) continue;
              *count = threads;
              // The value the stage runs with, as report.json's config and config.yaml echo it:
              // a run again from that config.yaml then gets the same thread counts.
              option->default_str(std::to_string(threads));
            }
          },
          "Threads of every stage whose own flag is not given (" +
              std::to_string(thread_counts.size()) + " thread counts); 0 leaves them")
      ->default_str("0")
      ->group("General")
      ->check(CLI::NonNegativeNumber);
}

nlohmann::json OptionsTable::toJson() const {
  nlohmann::json json = nlohmann::json::object();
  for (const OptionGroup& group : groups_) {
    for (const OptionField& row : group.fields) {
      if (!row.value) continue;
      json[nlohmann::json::json_pointer(group.path + "/" + row.field)] = row.value();
    }
  }
  return json;
}

void OptionsTable::validate() const {
  // Nested structs come after their parents in groups_, so reverse order checks them first and
  // an error lands in the group of the struct that owns the field.
  for (auto group = groups_.rbegin(); group != groups_.rend(); ++group) {
    try {
      group->validate();
    } catch (const InvalidOptions& e) {
      if (e.structName() != group->struct_name) throw;
      const auto row = std::find_if(group->fields.begin(), group->fields.end(),
                                    [&](const OptionField& f) { return f.field == e.field(); });
      if (row == group->fields.end() || row->flag.empty()) throw;
      throw e.withFlag(row->flag);
    }
  }
}

}  // namespace curvesfm
