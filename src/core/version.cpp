// The version of railcrash and the commit it was built from (version_text.cpp: the libraries').
#include "railcrash/core/version.hpp"

#include "build_commit.hpp"  // RAILCRASH_COMMIT (cmake/build_commit.cmake)

#ifndef RAILCRASH_VERSION
#define RAILCRASH_VERSION "unknown"
#endif

namespace railcrash {

std::string version_number() { return RAILCRASH_VERSION; }

std::string build_commit() { return RAILCRASH_COMMIT; }

}  // namespace railcrash
