// Debian's serial HDF5, loaded when a run first asks for it (`--format hdf5`) or the report reads
// a run folder's timeseries.h5, not at start-up.
//
// libhdf5_serial.so.103 brings in libcurl and libcrypto (its read-only S3 driver) and, through
// them, 20-odd more libraries (GnuTLS, Kerberos, LDAP, SSH, ...): linked in the ordinary way, the
// dynamic loader mapped and relocated them all before main, most of the CPU time of a short
// railcrash run (bench/HISTORY.md "Start-up"). So nothing links it: this file
// defines the HDF5 functions and the four global identifiers that hdf5_file.cpp uses, with the
// signatures of <hdf5.h> (the compiler checks them), and each forwards to the library's own,
// found with dlopen/dlsym on the first call. The identifiers (H5T_NATIVE_DOUBLE_g, ...) are read
// by HDF5's macros right after a call of H5open(), whose forwarder copies the library's values
// in. Hidden visibility keeps these names inside the executable, librailcrash.so or the Python
// module: the library's own calls never land here. When the library cannot be loaded, the first
// call throws an InputError saying what to install.
#include <dlfcn.h>
#include <hdf5.h>

#include <mutex>
#include <string>

#include "railcrash/core/error.hpp"

#ifndef RAILCRASH_HDF5_LIBRARY
#error "RAILCRASH_HDF5_LIBRARY (the serial HDF5's soname, set by CMakeLists.txt) is not defined"
#endif

namespace {

void* hdf5_library() {
  static void* library = nullptr;
  static std::string failure;
  static std::once_flag loaded;
  std::call_once(loaded, [] {
    library = dlopen(RAILCRASH_HDF5_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (!library) failure = dlerror();
  });
  if (!library)
    throw railcrash::InputError("HDF5 (--format hdf5, or the report of such a run's timeseries.h5): cannot load it (" + failure +
                                "); install Debian's libhdf5-103-1 (scripts/install-deps.sh does), or leave out "
                                "--format hdf5 for the CSV files");
  return library;
}

void* hdf5_symbol(const char* name) {
  void* symbol = dlsym(hdf5_library(), name);
  if (!symbol)
    throw railcrash::InputError(std::string("--format hdf5: the HDF5 library ") + RAILCRASH_HDF5_LIBRARY + " has no " +
                                name + "; install the version this railcrash was built with (libhdf5-dev)");
  return symbol;
}

/// Calls the library's function of the same name and type as Forwarder (the function defined below).
template <auto Forwarder, typename... Arguments>
auto forward(const char* name, Arguments... arguments) {
  static const auto function = reinterpret_cast<decltype(Forwarder)>(hdf5_symbol(name));
  return function(arguments...);
}

}  // namespace

#pragma GCC visibility push(hidden)
extern "C" {

hid_t H5T_NATIVE_DOUBLE_g = -1;
hid_t H5T_C_S1_g = -1;
hid_t H5P_CLS_DATASET_CREATE_ID_g = -1;
hid_t H5P_CLS_FILE_ACCESS_ID_g = -1;

herr_t H5open(void) {
  const herr_t status = forward<&H5open>("H5open");
  static std::once_flag copied;
  if (status >= 0)
    std::call_once(copied, [] {
      H5T_NATIVE_DOUBLE_g = *static_cast<hid_t*>(hdf5_symbol("H5T_NATIVE_DOUBLE_g"));
      H5T_C_S1_g = *static_cast<hid_t*>(hdf5_symbol("H5T_C_S1_g"));
      H5P_CLS_DATASET_CREATE_ID_g = *static_cast<hid_t*>(hdf5_symbol("H5P_CLS_DATASET_CREATE_ID_g"));
      H5P_CLS_FILE_ACCESS_ID_g = *static_cast<hid_t*>(hdf5_symbol("H5P_CLS_FILE_ACCESS_ID_g"));
    });
  return status;
}

herr_t H5check_version(unsigned major, unsigned minor, unsigned release) {
  return forward<&H5check_version>("H5check_version", major, minor, release);
}
herr_t H5dont_atexit(void) { return forward<&H5dont_atexit>("H5dont_atexit"); }
int H5Idec_ref(hid_t id) { return forward<&H5Idec_ref>("H5Idec_ref", id); }

herr_t H5Eclear2(hid_t stack) { return forward<&H5Eclear2>("H5Eclear2", stack); }
herr_t H5Eset_auto2(hid_t stack, H5E_auto2_t handler, void* data) {
  return forward<&H5Eset_auto2>("H5Eset_auto2", stack, handler, data);
}
herr_t H5Ewalk2(hid_t stack, H5E_direction_t direction, H5E_walk2_t walker, void* data) {
  return forward<&H5Ewalk2>("H5Ewalk2", stack, direction, walker, data);
}

hid_t H5Fcreate(const char* name, unsigned flags, hid_t creation, hid_t access) {
  return forward<&H5Fcreate>("H5Fcreate", name, flags, creation, access);
}
herr_t H5Fflush(hid_t object, H5F_scope_t scope) { return forward<&H5Fflush>("H5Fflush", object, scope); }
herr_t H5Fclose(hid_t file) { return forward<&H5Fclose>("H5Fclose", file); }

hid_t H5Pcreate(hid_t property_class) { return forward<&H5Pcreate>("H5Pcreate", property_class); }
herr_t H5Pset_chunk(hid_t properties, int rank, const hsize_t dimensions[]) {
  return forward<&H5Pset_chunk>("H5Pset_chunk", properties, rank, dimensions);
}
herr_t H5Pset_libver_bounds(hid_t properties, H5F_libver_t low, H5F_libver_t high) {
  return forward<&H5Pset_libver_bounds>("H5Pset_libver_bounds", properties, low, high);
}

hid_t H5Screate(H5S_class_t type) { return forward<&H5Screate>("H5Screate", type); }
hid_t H5Screate_simple(int rank, const hsize_t dimensions[], const hsize_t maximum[]) {
  return forward<&H5Screate_simple>("H5Screate_simple", rank, dimensions, maximum);
}
herr_t H5Sselect_hyperslab(hid_t space, H5S_seloper_t operation, const hsize_t start[], const hsize_t stride[],
                           const hsize_t count[], const hsize_t block[]) {
  return forward<&H5Sselect_hyperslab>("H5Sselect_hyperslab", space, operation, start, stride, count, block);
}

hid_t H5Tcopy(hid_t type) { return forward<&H5Tcopy>("H5Tcopy", type); }
hid_t H5Tcreate(H5T_class_t type_class, size_t size) { return forward<&H5Tcreate>("H5Tcreate", type_class, size); }
herr_t H5Tinsert(hid_t parent, const char* name, size_t offset, hid_t member) {
  return forward<&H5Tinsert>("H5Tinsert", parent, name, offset, member);
}
herr_t H5Tset_size(hid_t type, size_t size) { return forward<&H5Tset_size>("H5Tset_size", type, size); }
herr_t H5Tset_cset(hid_t type, H5T_cset_t cset) { return forward<&H5Tset_cset>("H5Tset_cset", type, cset); }
herr_t H5Tclose(hid_t type) { return forward<&H5Tclose>("H5Tclose", type); }

hid_t H5Acreate2(hid_t location, const char* name, hid_t type, hid_t space, hid_t creation, hid_t access) {
  return forward<&H5Acreate2>("H5Acreate2", location, name, type, space, creation, access);
}
herr_t H5Awrite(hid_t attribute, hid_t memory_type, const void* data) {
  return forward<&H5Awrite>("H5Awrite", attribute, memory_type, data);
}

hid_t H5Dcreate2(hid_t location, const char* name, hid_t type, hid_t space, hid_t link_properties,
                 hid_t creation, hid_t access) {
  return forward<&H5Dcreate2>("H5Dcreate2", location, name, type, space, link_properties, creation, access);
}
herr_t H5Dset_extent(hid_t dataset, const hsize_t size[]) { return forward<&H5Dset_extent>("H5Dset_extent", dataset, size); }
hid_t H5Dget_space(hid_t dataset) { return forward<&H5Dget_space>("H5Dget_space", dataset); }
herr_t H5Dwrite(hid_t dataset, hid_t memory_type, hid_t memory_space, hid_t file_space, hid_t transfer, const void* data) {
  return forward<&H5Dwrite>("H5Dwrite", dataset, memory_type, memory_space, file_space, transfer, data);
}
herr_t H5Dwrite_chunk(hid_t dataset, hid_t transfer, uint32_t filters, const hsize_t* offset, size_t bytes,
                      const void* data) {
  return forward<&H5Dwrite_chunk>("H5Dwrite_chunk", dataset, transfer, filters, offset, bytes, data);
}
herr_t H5Dclose(hid_t dataset) { return forward<&H5Dclose>("H5Dclose", dataset); }

// Reading back (Hdf5Reader: the report of a --format hdf5 run folder).
hid_t H5Fopen(const char* name, unsigned flags, hid_t access) { return forward<&H5Fopen>("H5Fopen", name, flags, access); }
htri_t H5Lexists(hid_t location, const char* name, hid_t link_access) {
  return forward<&H5Lexists>("H5Lexists", location, name, link_access);
}
htri_t H5Aexists(hid_t object, const char* name) { return forward<&H5Aexists>("H5Aexists", object, name); }
hid_t H5Aopen(hid_t object, const char* name, hid_t access) { return forward<&H5Aopen>("H5Aopen", object, name, access); }
herr_t H5Aread(hid_t attribute, hid_t memory_type, void* data) { return forward<&H5Aread>("H5Aread", attribute, memory_type, data); }
hid_t H5Dopen2(hid_t location, const char* name, hid_t access) { return forward<&H5Dopen2>("H5Dopen2", location, name, access); }
hid_t H5Dget_type(hid_t dataset) { return forward<&H5Dget_type>("H5Dget_type", dataset); }
herr_t H5Dread(hid_t dataset, hid_t memory_type, hid_t memory_space, hid_t file_space, hid_t transfer, void* data) {
  return forward<&H5Dread>("H5Dread", dataset, memory_type, memory_space, file_space, transfer, data);
}
herr_t H5Dvlen_reclaim(hid_t type, hid_t space, hid_t transfer, void* data) {
  return forward<&H5Dvlen_reclaim>("H5Dvlen_reclaim", type, space, transfer, data);
}
int H5Sget_simple_extent_ndims(hid_t space) { return forward<&H5Sget_simple_extent_ndims>("H5Sget_simple_extent_ndims", space); }
int H5Sget_simple_extent_dims(hid_t space, hsize_t dimensions[], hsize_t maximum[]) {
  return forward<&H5Sget_simple_extent_dims>("H5Sget_simple_extent_dims", space, dimensions, maximum);
}
H5T_class_t H5Tget_class(hid_t type) { return forward<&H5Tget_class>("H5Tget_class", type); }
int H5Tget_nmembers(hid_t type) { return forward<&H5Tget_nmembers>("H5Tget_nmembers", type); }
char* H5Tget_member_name(hid_t type, unsigned member) { return forward<&H5Tget_member_name>("H5Tget_member_name", type, member); }
H5T_class_t H5Tget_member_class(hid_t type, unsigned member) {
  return forward<&H5Tget_member_class>("H5Tget_member_class", type, member);
}
herr_t H5free_memory(void* memory) { return forward<&H5free_memory>("H5free_memory", memory); }

}  // extern "C"
#pragma GCC visibility pop
