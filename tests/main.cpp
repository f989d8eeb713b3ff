// The unit tests' runner: Catch2's own, with two of its warnings always on, so that a test case
// (or a section) that makes no assertion fails ("No assertions in test case"), and so does a test
// spec that selects no test case ("No test cases matched", exit 2): CTest gives each test case's
// name as the spec, and a name CMake splits at ';' selects none. Catch2 v2 takes only one --warn
// on its command line, hence here rather than in catch_discover_tests' EXTRA_ARGS.
// tests/check_test_names.py checks that both are in force.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

int main(int argc, char* argv[]) {
  Catch::Session session;
  if (const int status = session.applyCommandLine(argc, argv); status != 0) return status;
  Catch::ConfigData& config = session.configData();
  config.warnings = static_cast<Catch::WarnAbout::What>(config.warnings | Catch::WarnAbout::NoAssertions |
                                                        Catch::WarnAbout::NoTests);
  return session.run();
}

// Hidden (not run by default, not a CTest entry): check_test_names.py runs it to see that a test
// case which makes no assertion fails. It must stay empty.
TEST_CASE("runner self-check: a test case that makes no assertion fails", "[.runner_self_check]") {}
