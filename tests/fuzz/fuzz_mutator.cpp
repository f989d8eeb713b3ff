// Structure-aware mutations for the fuzz target (libFuzzer builds only: it calls
// LLVMFuzzerMutate). A model's behaviour hangs on its numbers, which byte flips rarely turn
// into the values that break arithmetic, so with some probability a number of the text is
// replaced by an interesting one (zero, signed zero, tiny, huge, not finite, scaled, sign
// flipped); otherwise libFuzzer's own mutations apply. The crossover splices whole lines of
// two models, which keeps their YAML indentation meaningful more often than byte splices.
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace {

/// Where a number is written in the text: [begin, end).
struct NumberSpan {
  std::size_t begin, end;
};

bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

/// The decimal numbers of `text` (sign, digits, fraction, exponent), not parts of words.
std::vector<NumberSpan> find_numbers(const std::string& text) {
  std::vector<NumberSpan> spans;
  std::size_t i = 0;
  while (i < text.size()) {
    const bool word_before = i > 0 && (std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '_');
    std::size_t j = i;
    if (text[j] == '-' || text[j] == '+') ++j;
    bool has_digit = false;
    while (j < text.size() && (is_digit(text[j]) || text[j] == '.')) has_digit = is_digit(text[j++]) || has_digit;
    if (!has_digit || word_before) {
      i = j > i ? j : i + 1;
      continue;
    }
    if (j < text.size() && (text[j] == 'e' || text[j] == 'E')) {
      std::size_t k = j + 1;
      if (k < text.size() && (text[k] == '-' || text[k] == '+')) ++k;
      const std::size_t exponent_start = k;
      while (k < text.size() && is_digit(text[k])) ++k;
      if (k > exponent_start) j = k;
    }
    spans.push_back({i, j});
    i = j;
  }
  return spans;
}

/// A replacement for the number `original`: one of the values that break arithmetic, or the
/// original scaled by 10 or 0.1, or with its sign flipped.
std::string interesting_number(const std::string& original, std::minstd_rand& random) {
  static const char* const kValues[] = {"0", "-0", "-1", "1", "1e-300", "1e308", "-1e308", ".nan", ".inf", "-.inf",
                                        "nan", "inf", "99999999999999999999", "-9223372036854775809", "2147483648",
                                        "4.9e-324", "1e-8"};
  constexpr std::size_t kValueCount = sizeof(kValues) / sizeof(kValues[0]);
  const std::size_t choice = random() % (kValueCount + 3);
  if (choice < kValueCount) return kValues[choice];
  const double value = std::strtod(original.c_str(), nullptr);
  char buffer[64];
  if (choice == kValueCount) std::snprintf(buffer, sizeof buffer, "%.17g", value * 10.0);
  else if (choice == kValueCount + 1) std::snprintf(buffer, sizeof buffer, "%.17g", value * 0.1);
  else return original[0] == '-' ? original.substr(1) : "-" + original;
  return buffer;
}

/// Copies `text` into data when it fits in max_size; returns the new size (0: did not fit).
std::size_t store(const std::string& text, std::uint8_t* data, std::size_t max_size) {
  if (text.empty() || text.size() > max_size) return 0;
  std::memcpy(data, text.data(), text.size());
  return text.size();
}

}  // namespace

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
  std::minstd_rand random(seed);
  if (random() % 3 == 0) {
    std::string text(reinterpret_cast<const char*>(data), size);
    const std::vector<NumberSpan> numbers = find_numbers(text);
    if (!numbers.empty()) {
      const NumberSpan span = numbers[random() % numbers.size()];
      text.replace(span.begin, span.end - span.begin,
                   interesting_number(text.substr(span.begin, span.end - span.begin), random));
      if (const std::size_t new_size = store(text, data, max_size)) return new_size;
    }
  }
  return LLVMFuzzerMutate(data, size, max_size);
}

extern "C" std::size_t LLVMFuzzerCustomCrossOver(const std::uint8_t* data1, std::size_t size1, const std::uint8_t* data2,
                                                 std::size_t size2, std::uint8_t* out, std::size_t max_out_size,
                                                 unsigned int seed) {
  std::minstd_rand random(seed);
  const auto line_starts = [](const std::string& text) {
    std::vector<std::size_t> starts{0};
    for (std::size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') starts.push_back(i + 1);
    return starts;
  };
  const std::string first(reinterpret_cast<const char*>(data1), size1);
  const std::string second(reinterpret_cast<const char*>(data2), size2);
  const std::vector<std::size_t> first_lines = line_starts(first);
  const std::vector<std::size_t> second_lines = line_starts(second);
  // The first model's lines up to a random line, then the second's from a random line on.
  const std::size_t cut = first_lines[random() % first_lines.size()];
  const std::size_t resume = second_lines[random() % second_lines.size()];
  return store(first.substr(0, cut) + second.substr(resume), out, max_out_size);
}
