// `railcrash --version`: railcrash's version and those of the libraries it was built with, from
// their headers at build time. (Apart from version.cpp so that the fuzz target, which records
// the version in provenance, links without the report's assets.)
#include <klu.h>
#include <sundials/sundials_config.h>

#include <Eigen/Core>

#include "railcrash/core/version.hpp"
#include "railcrash/report/assets.hpp"

#ifdef RAILCRASH_HDF5_LIBRARY
#include <H5public.h>
#endif

#ifndef RAILCRASH_VERSION
#define RAILCRASH_VERSION "unknown"
#endif

namespace railcrash {

std::string version_text() {
  const auto number = [](int value) { return std::to_string(value); };
  std::string text = "railcrash " RAILCRASH_VERSION;
  text += build_commit().empty() ? "\n" : " (commit " + build_commit() + ")\n";
  text += "SUNDIALS " SUNDIALS_VERSION " (IDAS)\n";
  text += "SuiteSparse " + number(SUITESPARSE_MAIN_VERSION) + "." + number(SUITESPARSE_SUB_VERSION) + "." +
          number(SUITESPARSE_SUBSUB_VERSION) + " (KLU " + number(KLU_MAIN_VERSION) + "." + number(KLU_SUB_VERSION) + "." +
          number(KLU_SUBSUB_VERSION) + ")\n";
  text += "Eigen " + number(EIGEN_WORLD_VERSION) + "." + number(EIGEN_MAJOR_VERSION) + "." + number(EIGEN_MINOR_VERSION) + "\n";
#ifdef RAILCRASH_HDF5_LIBRARY
  text += "HDF5 " + number(H5_VERS_MAJOR) + "." + number(H5_VERS_MINOR) + "." + number(H5_VERS_RELEASE) +
          " (--format hdf5; " RAILCRASH_HDF5_LIBRARY " loaded when first used)\n";
#else
  text += "HDF5: none (built without libhdf5-dev: no --format hdf5)\n";
#endif
  text += std::string("report plots: ") + (report::assets::kHaveLibrary ? report::assets::kLibraryName : "none (built without npm)");
  return text;
}

}  // namespace railcrash
