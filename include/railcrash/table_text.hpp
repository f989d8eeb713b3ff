// Numbers and text for the Markdown and CSV tables the studies write (sensitivity, readings).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

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

}  // namespace railcrash
