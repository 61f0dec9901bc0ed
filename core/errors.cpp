#include "core/errors.h"

#include <cmath>
#include <locale>
#include <sstream>

namespace curvesfm {

IoError::IoError(const std::string& path, const std::string& problem)
    : Error("IoError: " + path + ": " + problem) {}

ParseError::ParseError(const std::string& path, int line, const std::string& expected,
                       const std::string& found)
    : Error("ParseError: " + path + (line > 0 ? ":" + std::to_string(line) : std::string()) +
            ": expected " + expected + ", found " + found),
      path_(path),
      line_(line) {}

InvalidOptions::InvalidOptions(const std::string& struct_name, const std::string& field,
                               const std::string& value, const std::string& constraint)
    : InvalidOptions(
          "InvalidOptions: " + struct_name + "." + field + " = " + value + ": " + constraint,
          struct_name, field, value, constraint) {}

InvalidOptions::InvalidOptions(const std::string& message, const std::string& struct_name,
                               const std::string& field, const std::string& value,
                               const std::string& constraint)
    : Error(message),
      struct_name_(struct_name),
      field_(field),
      value_(value),
      constraint_(constraint) {}

InvalidOptions InvalidOptions::withFlag(const std::string& flag) const {
  return InvalidOptions("InvalidOptions: --" + flag + " = " + value_ + ": " + constraint_ + " (" +
                            struct_name_ + "." + field_ + ")",
                        struct_name_, field_, value_, constraint_);
}

std::string formatOptionValue(double value) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << value;
  return out.str();
}

void OptionCheck::operator()(bool ok, std::string_view field, double value,
                             std::string_view constraint) const {
  if (!ok) {
    throw InvalidOptions(struct_name_, std::string(field), formatOptionValue(value),
                         std::string(constraint));
  }
}

void OptionCheck::positive(std::string_view field, double value) const {
  (*this)(value > 0.0 && std::isfinite(value), field, value, "must be > 0 and finite");
}

void OptionCheck::nonNegative(std::string_view field, double value) const {
  (*this)(value >= 0.0 && std::isfinite(value), field, value, "must be >= 0 and finite");
}

void OptionCheck::finite(std::string_view field, double value) const {
  (*this)(std::isfinite(value), field, value, "must be finite");
}

}  // namespace curvesfm
