// Errors: input problems a user can fix are thrown as InputError (exit status 2 from the
// command line, message names file, line, element or body and what to change); broken
// internal invariants are RAILCRASH_DEMAND failures (a bug in railcrash, not in the model).
#pragma once

#include <stdexcept>
#include <string>

namespace railcrash {

/// Where something was written in a model file (line is 1-based; 0 = unknown).
struct SourceLocation {
  std::string file;
  int line = 0;
  std::string prefix() const {  // "model.yaml:12: "
    if (file.empty()) return "";
    return line > 0 ? file + ":" + std::to_string(line) + ": " : file + ": ";
  }
};

/// A model or command-line input the user must change.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The solver could not continue (integrator failure, singular system at run time, ...).
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

[[noreturn]] void demand_failed(const char* condition, const char* file, int line);

}  // namespace railcrash

/// Internal invariant: a failure is a bug in railcrash.
#define RAILCRASH_DEMAND(condition) \
  do { if (!(condition)) ::railcrash::demand_failed(#condition, __FILE__, __LINE__); } while (0)
