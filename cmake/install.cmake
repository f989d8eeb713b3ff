# `cmake --install build --prefix P` and `cpack` (run from build/): the command-line program,
# the shared and static libraries with the public headers, and the CMake package that
# find_package(railcrash) reads:
#   P/bin/railcrash (and railcrash-mpi, the MPI build it runs for a sweep under mpirun)
#   P/lib/librailcrash.so.0.1, librailcrash.a
#   P/include/railcrash/api.hpp, core/error.hpp
#   P/lib/cmake/railcrash/railcrashConfig.cmake (targets railcrash::railcrash, railcrash::railcrash_static)
# Debian packages (cpack -G DEB): railcrash (program and shared library), railcrash-dev
# (headers, static library, CMake package) and python3-railcrash (when the module is built).
include(CMakePackageConfigHelpers)

set(RAILCRASH_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/railcrash)

install(TARGETS railcrash RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
if(TARGET railcrash_mpi)  # beside railcrash, which execs it for a sweep under mpirun
  install(TARGETS railcrash_mpi RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
endif()
install(TARGETS railcrash_shared EXPORT railcrashTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT runtime NAMELINK_COMPONENT development)
install(TARGETS railcrash_core EXPORT railcrashTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development)
install(FILES include/railcrash/api.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/railcrash COMPONENT development)
install(FILES include/railcrash/core/error.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/railcrash/core COMPONENT development)
install(EXPORT railcrashTargets NAMESPACE railcrash:: DESTINATION ${RAILCRASH_CMAKE_DIR} COMPONENT development)
configure_package_config_file(cmake/railcrashConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/railcrashConfig.cmake
  INSTALL_DESTINATION ${RAILCRASH_CMAKE_DIR})
# Before 1.0 a minor version may change the interface.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/railcrashConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/railcrashConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/railcrashConfigVersion.cmake
  DESTINATION ${RAILCRASH_CMAKE_DIR} COMPONENT development)

# ---- Debian packages ----
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME railcrash)
set(CPACK_PACKAGE_VENDOR "railcrash")
set(CPACK_PACKAGE_CONTACT "railcrash maintainers <railcrash@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "planar rail-vehicle crash dynamics (IITRAIN elements, SUNDIALS IDAS + KLU)")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime development)
if(TARGET railcrash_python)
  list(APPEND CPACK_COMPONENTS_ALL python)
endif()
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# Shared-library dependencies (SUNDIALS, KLU, yaml-cpp, libstdc++) from dpkg-shlibdeps.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME railcrash)
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_NAME railcrash-dev)
set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-railcrash)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SECTION science)
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
# find_package(railcrash) finds these again (railcrashConfig.cmake); KLU (libsuitesparse-dev)
# through the SUNDIALS::KLU target that SUNDIALS' configuration defines.
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_DEPENDS
  "railcrash (= ${PROJECT_VERSION}), libsundials-dev (>= 6), libsuitesparse-dev, libyaml-cpp-dev, libeigen3-dev (>= 3.3), cmake (>= 3.18)")
if(RAILCRASH_HDF5)  # loaded by its soname for --format hdf5 (src/results/hdf5_library.cpp), so shlibdeps does not see it
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS "libhdf5-103-1")
endif()
set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "python3 (>= 3.11), python3 (<< 3.12), python3-numpy")
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION "railcrash command-line program and shared library")
set(CPACK_COMPONENT_DEVELOPMENT_DESCRIPTION "railcrash C++ headers, static library and CMake package")
set(CPACK_COMPONENT_PYTHON_DESCRIPTION "railcrash Python module (import railcrash)")
include(CPack)
