// The version of railcrash and of the libraries it was built with (`railcrash --version`).
#pragma once

#include <string>

namespace railcrash {

/// Lines: "railcrash X.Y.Z", then the SUNDIALS, SuiteSparse (with its KLU) and Eigen versions
/// from their headers at build time, and the report's plotting library.
std::string version_text();

}  // namespace railcrash
