// Numbers and text for the Markdown and CSV tables the studies write (sensitivity, readings).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace railcrash {

/// `value` printed with a printf format; "n/a" for NaN, "inf" for infinities.
inline std::string table_number(double value, const char* format = "%.3f") {
  if (std::isnan(value)) return "n/a";
  if (std::isinf(value)) return value > 0.0 ? "inf" : "-inf";
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

/// A CSV field for a number: empty for NaN, else `digits` significant digits.
inline std::string csv_number(double value, const char* format = "%.10g") {
  return std::isnan(value) ? "" : table_number(value, format);
}

/// A CSV field for text: quoted, inner quotes doubled.
inline std::string csv_text(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

/// Fields of one CSV line (RFC 4180 quoting: quotes removed, doubled quotes made single).
inline std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

}  // namespace railcrash
