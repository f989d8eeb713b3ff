#include "railcrash/studies/run_count.hpp"

#include <limits>

#include "railcrash/core/error.hpp"

namespace railcrash {

std::optional<std::size_t> multiply_counts(std::optional<std::size_t> a, std::optional<std::size_t> b) {
  if (!a || !b) return (a && *a == 0) || (b && *b == 0) ? std::optional<std::size_t>(0) : std::nullopt;
  std::size_t product = 0;
  if (__builtin_mul_overflow(*a, *b, &product)) return std::nullopt;
  return product;
}

std::optional<std::size_t> add_counts(std::optional<std::size_t> a, std::optional<std::size_t> b) {
  if (!a || !b) return std::nullopt;
  std::size_t sum = 0;
  if (__builtin_add_overflow(*a, *b, &sum)) return std::nullopt;
  return sum;
}

std::optional<std::size_t> factorial_count(const std::vector<std::size_t>& level_counts) {
  if (level_counts.empty()) return 0;
  std::optional<std::size_t> total = 1;
  for (const std::size_t n : level_counts) total = multiply_counts(total, n);
  return total;
}

void require_run_count(std::optional<std::size_t> count, std::size_t limit, const std::string& what) {
  if (limit == 0 || (count && *count <= limit)) return;
  const std::string runs = count ? std::to_string(*count) + " runs"
                                 : "more than " + std::to_string(std::numeric_limits<std::size_t>::max()) + " runs";
  throw InputError(what + ": " + runs + ", more than the limit of " + std::to_string(limit) +
                   " (--max-runs); make the plan smaller, or raise --max-runs if the runs are meant");
}

}  // namespace railcrash
