#include "core/text_records.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <locale>
#include <sstream>
#include <system_error>

#include "core/errors.h"

namespace curvesfm {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
// Longest token quoted verbatim in a message; binary junk must not flood the terminal.
constexpr std::size_t kMaxQuotedToken = 40;

}  // namespace

std::ifstream openForReading(const std::string& path) {
  // An ifstream opens a directory without complaint on Linux and only fails on the first read,
  // which would look like an empty file.
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) {
    throw IoError(path, "cannot open for reading (it is a directory)");
  }
  std::ifstream in(path);
  if (!in) throw IoError(path, "cannot open for reading");
  return in;
}

TextFields splitFields(std::string_view line, std::string_view separators) {
  // '\r' is a separator so that CRLF files parse like LF files.
  TextFields fields;
  std::size_t begin = line.find_first_not_of(separators);
  while (begin != std::string_view::npos) {
    const std::size_t end = std::min(line.find_first_of(separators, begin), line.size());
    fields.push_back(line.substr(begin, end - begin));
    begin = line.find_first_not_of(separators, end);
  }
  return fields;
}

std::string_view withoutByteOrderMark(std::string_view line) {
  if (line.substr(0, kUtf8Bom.size()) == kUtf8Bom) line.remove_prefix(kUtf8Bom.size());
  return line;
}

// std::from_chars is locale independent, unlike strtod, whose decimal separator follows the
// global C locale.
std::optional<double> parseFiniteNumber(std::string_view token) {
  // from_chars rejects the leading '+' that strtod and printf("%+f") produce.
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+') {
    token.remove_prefix(1);
  }
  double value = 0.0;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, value);
  if (error != std::errc() || stop != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::string quoteToken(std::string_view token) {
  if (token.size() > kMaxQuotedToken) {
    return "\"" + std::string(token.substr(0, kMaxQuotedToken)) + "...\"";
  }
  return "\"" + std::string(token) + "\"";
}

std::string formatNumber(double value) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << std::setprecision(std::numeric_limits<double>::digits10) << value;
  return out.str();
}

void requireFieldCount(const std::string& path, int line, const TextFields& fields,
                       std::size_t count, const char* format) {
  if (fields.size() != count) {
    throw ParseError(path, line, std::to_string(count) + " fields \"" + format + "\"",
                     std::to_string(fields.size()));
  }
}

double numberField(const std::string& path, int line, const TextFields& fields, std::size_t index,
                   const char* name) {
  if (const std::optional<double> value = parseFiniteNumber(fields[index])) return *value;
  throw ParseError(path, line, "a number in field " + std::to_string(index + 1) + " (" + name + ")",
                   quoteToken(fields[index]));
}

}  // namespace curvesfm
