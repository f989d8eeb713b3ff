// `railcrash report --pdf` (issue 39 item 7): the report page printed to PDF by Debian's
// Chromium, headless (`chromium --headless --print-to-pdf`), beside the page (report.pdf).
//
// Chromium is found on PATH (chromium, then chromium-browser); without it, an InputError says
// to install it (`apt-get install chromium`). It runs with a fresh profile in a temporary
// folder, in its own process group, and a virtual time budget: Chromium runs the page's script
// and the charts' drawing to the end (virtual time advances as soon as nothing is pending)
// before it prints. The page's print style (report.css, @media print) hides the controls and
// keeps each chart on one page. The PDF is written under a temporary name and renamed when
// Chromium has finished and it starts with "%PDF-"; otherwise (Chromium fails, is killed or
// exceeds the time limit) an InputError gives Chromium's last lines of output.
#pragma once

#include <string>

namespace railcrash::report {

struct PdfOptions {
  int virtual_time_budget_ms = 10000;  // [ms] of the page's (virtual) time before printing
  int timeout_seconds = 180;           // [s] of real time before chromium is killed
};

/// The chromium executable on PATH ("" when there is none).
std::string find_chromium();

/// Prints the page at html_path to the PDF beside it (report.html -> report.pdf); returns its path.
std::string print_pdf(const std::string& html_path, const PdfOptions& options = {});

}  // namespace railcrash::report
