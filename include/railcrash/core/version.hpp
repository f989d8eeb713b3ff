// The version of railcrash and of the libraries it was built with (`railcrash --version`).
#pragma once

#include <string>

namespace railcrash {

/// "X.Y.Z": the project's version (CMakeLists.txt).
std::string version_number();
/// The commit of the git checkout it was built from ("abc1234def56", "-dirty" appended when
/// tracked files differed from it), "" when built from sources outside a checkout.
std::string build_commit();

/// Lines: "railcrash X.Y.Z" (and "commit C" when built from a checkout), then the SUNDIALS, SuiteSparse (with its KLU) and Eigen versions
/// from their headers at build time, and the report's plotting library.
std::string version_text();

}  // namespace railcrash
