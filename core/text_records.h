#pragma once

#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/errors.h"

namespace curvesfm {

// The line reader and number parsing behind every text reader in core/ (dataset_io,
// image_sequence, colmap_model), so that they all accept the same files and word their errors
// alike (dataset_io.h, "Errors"). Text files: a line whose first non-blank character is '#' is a
// comment; blank lines are skipped; fields are separated by spaces or tabs; CRLF line ends and a
// UTF-8 byte order mark are accepted. Numbers are parsed locale independently and must be finite,
// with no trailing characters.

using TextFields = std::vector<std::string_view>;

/// Opens `path` for reading; IoError "<path>: cannot open for reading" (also for a directory,
/// which an ifstream would open and read as empty).
std::ifstream openForReading(const std::string& path);

/// What separates fields: blanks ('\r' counts as one), and for CSV files commas too (files
/// without quoted fields, as EuRoC's data.csv).
inline constexpr std::string_view kBlankSeparators = " \t\r\v\f";
inline constexpr std::string_view kCsvSeparators = " \t\r\v\f,";
/// The fields of `line`, split at runs of `separators`.
TextFields splitFields(std::string_view line, std::string_view separators = kBlankSeparators);

/// Removes a UTF-8 byte order mark from the start of `line`.
std::string_view withoutByteOrderMark(std::string_view line);

/// Calls visit(line_number, fields) for every line of `path` that is neither blank nor a comment,
/// line numbers 1-based, fields split at `separators`. IoError if the file cannot be opened or
/// read.
template <class Visit>
void forEachRecord(const std::string& path, Visit&& visit,
                   std::string_view separators = kBlankSeparators);

/// The finite number `token` spells (a leading '+' allowed), or nothing.
std::optional<double> parseFiniteNumber(std::string_view token);

/// `token` in double quotes for a message, cut to 40 characters.
std::string quoteToken(std::string_view token);

/// `value` with 15 significant digits in the C locale, for messages.
std::string formatNumber(double value);

/// ParseError "<path>:<line>: expected <count> fields "<format>", found <n>" unless `fields` has
/// exactly `count` fields.
void requireFieldCount(const std::string& path, int line, const TextFields& fields,
                       std::size_t count, const char* format);

/// fields[index] as a finite number; ParseError "<path>:<line>: expected a number in field <k>
/// (<name>), found "<token>"" otherwise.
double numberField(const std::string& path, int line, const TextFields& fields, std::size_t index,
                   const char* name);

template <class Visit>
void forEachRecord(const std::string& path, Visit&& visit, std::string_view separators) {
  std::ifstream in = openForReading(path);
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    std::string_view view(line);
    if (line_number == 1) view = withoutByteOrderMark(view);
    const TextFields fields = splitFields(view, separators);
    if (fields.empty() || fields.front().front() == '#') continue;
    visit(line_number, fields);
  }
  if (in.bad()) throw IoError(path, "read error");
}

}  // namespace curvesfm
