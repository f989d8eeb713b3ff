// The report page's template, script and style, and the plotting library (uPlot from the npm
// registry, when the build fetched it), embedded at build time by cmake/embed_report_assets.cmake.
// Each is an array of string chunks ending with nullptr.
#pragma once

namespace railcrash::report::assets {

extern const char* const kTemplate[];
extern const char* const kScript[];
extern const char* const kStyle[];
extern const char* const kLibraryScript[];
extern const char* const kLibraryStyle[];
extern const bool kHaveLibrary;
extern const char* const kLibraryName;  // e.g. "uPlot-1.6.32", empty without

}  // namespace railcrash::report::assets
