#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

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
/// Message: "InvalidOptions: <Struct>.<field> = <value>: <constraint>", or, once the command line
/// knows which flag set the field (withFlag), "InvalidOptions: --<flag> = <value>: <constraint>
/// (<Struct>.<field>)".
class InvalidOptions : public Error {
 public:
  InvalidOptions(const std::string& struct_name, const std::string& field, const std::string& value,
                 const std::string& constraint);

  const std::string& structName() const { return struct_name_; }
  const std::string& field() const { return field_; }
  /// The same error worded for the user who typed `--flag` (given without dashes).
  InvalidOptions withFlag(const std::string& flag) const;

 private:
  InvalidOptions(const std::string& message, const std::string& struct_name,
                 const std::string& field, const std::string& value, const std::string& constraint);

  std::string struct_name_, field_, value_, constraint_;
};

/// A number as options messages print it (shortest round-trip-ish form, C locale).
std::string formatOptionValue(double value);

/// The checks of one options struct's validate(), so that every options error reads alike:
///
///   const OptionCheck require("CurveMapOptions");
///   require(window >= 1, "window", window, ">= 1");
///   require.positive("sigma", sigma);
///
/// Each throws InvalidOptions(struct, field, formatOptionValue(value), constraint) when the value
/// breaks the constraint. Write a condition as a positive comparison (value >= low) so NaN fails.
class OptionCheck {
 public:
  /// `struct_name` must outlive the check (a string literal): validate() runs in hot paths
  /// (once per segment and keyframe in registration), so nothing is copied or allocated unless
  /// a check fails.
  explicit OptionCheck(const char* struct_name) : struct_name_(struct_name) {}

  /// Throws unless `ok`.
  void operator()(bool ok, std::string_view field, double value, std::string_view constraint) const;
  /// > 0 and finite: "must be > 0 and finite".
  void positive(std::string_view field, double value) const;
  /// >= 0 and finite: "must be >= 0 and finite".
  void nonNegative(std::string_view field, double value) const;
  /// Finite: "must be finite".
  void finite(std::string_view field, double value) const;

 private:
  const char* struct_name_;
};

/// A violated internal invariant (a programmer error), thrown by CURVESFM_CHECK.
class CheckError : public Error {
 public:
  using Error::Error;
};

}  // namespace curvesfm
