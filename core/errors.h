#pragma once

#include <stdexcept>
#include <string>

namespace curvesfm {

/// Base of every error curvesfm throws on purpose. `what()` is one line, ready for a user.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// A file or folder that cannot be opened, read or written.
/// Message: "IoError: <path>: <what went wrong>".
class IoError : public Error {
 public:
  IoError(const std::string& path, const std::string& problem);
};

/// Malformed content in a file, located to the line (line 0 means "the file as a whole").
/// Message: "ParseError: <path>:<line>: expected <expected>, found <found>".
class ParseError : public Error {
 public:
  ParseError(const std::string& path, int line, const std::string& expected,
             const std::string& found);
  const std::string& path() const { return path_; }
  int line() const { return line_; }

 private:
  std::string path_;
  int line_;
};

/// An options struct holds a value outside its documented range.
/// Message: "InvalidOptions: <Struct>.<field> = <value>: <constraint>".
class InvalidOptions : public Error {
 public:
  InvalidOptions(const std::string& struct_name, const std::string& field, const std::string& value,
                 const std::string& constraint);
};

/// A number as options messages print it (shortest round-trip-ish form, C locale).
std::string formatOptionValue(double value);

/// For validate(): throws InvalidOptions(struct_name, field, formatOptionValue(value),
/// constraint) unless `ok`. Write `ok` as a positive comparison (value >= low) so NaN fails.
void requireOption(bool ok, const std::string& struct_name, const std::string& field, double value,
                   const std::string& constraint);

/// A violated internal invariant (a programmer error), thrown by CURVESFM_CHECK.
class CheckError : public Error {
 public:
  using Error::Error;
};

}  // namespace curvesfm
