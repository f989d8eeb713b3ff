// Line and scatter plots written as self-contained SVG files (no plotting dependency):
// simulated histories, force-stroke loops, error-versus-cost charts.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace railcrash::plot {

struct Series {
  std::string label;       // legend entry (empty: no entry)
  std::vector<double> x;   // same length as y; non-finite points break the line
  std::vector<double> y;
  bool markers = false;    // draw a marker at every point
  bool line = true;        // join the points
  bool dashed = false;
};

struct Figure {
  std::string title;
  std::string x_label;     // with its unit, e.g. "time [s]"
  std::string y_label;
  bool log_x = false;      // logarithmic axes take only positive values (others are skipped)
  bool log_y = false;
  std::vector<Series> series;
};

/// Writes the figure as an SVG file: an 800 x 500 plot, widened on the right by the legend's
/// column when a series has a label. Axes reach a twentieth of the data's span beyond it (log
/// axes: at least a twentieth of a decade), so no point or level line lies on the frame.
/// Throws std::runtime_error when the file cannot be written. Empty figures are written with
/// empty axes.
void write_svg(const Figure& figure, const std::filesystem::path& path);

}  // namespace railcrash::plot
