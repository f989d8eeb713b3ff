// A study's number of runs, counted without overflow and held to a limit before anything is
// generated: a plan of 2^64 runs is refused as too large instead of counting as 0, and one of
// 1e9 runs is refused before a list of them is built. The limit is the --max-runs option of the
// studies (sensitivity, readings; the sweep calls the same functions).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace railcrash {

/// The default of --max-runs: a plan with more runs is refused unless the option raises it.
constexpr std::size_t kDefaultMaxRuns = 1000000;

/// a x b, or nullopt when the product does not fit in std::size_t.
std::optional<std::size_t> multiply_counts(std::optional<std::size_t> a, std::optional<std::size_t> b);
/// a + b, or nullopt when the sum does not fit.
std::optional<std::size_t> add_counts(std::optional<std::size_t> a, std::optional<std::size_t> b);

/// The number of combinations of one level of each factor (the product of level_counts; 0 for
/// no factors, as a full factorial over none has no runs), or nullopt when it does not fit.
std::optional<std::size_t> factorial_count(const std::vector<std::size_t>& level_counts);

/// Throws InputError unless count (nullopt: more than std::size_t holds) is at most limit:
/// "WHAT: N runs, more than the limit of LIMIT (--max-runs); ...". limit 0 means no limit.
void require_run_count(std::optional<std::size_t> count, std::size_t limit, const std::string& what);

}  // namespace railcrash
