// SVG line plots: linear or logarithmic axes with "nice" tick values, one polyline per
// series (broken at non-finite or, on log axes, non-positive points), optional markers,
// a legend. Coordinates are computed here; the SVG is plain text.
#include "railcrash/results/plot.hpp"

#include "railcrash/core/whole_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace railcrash::plot {
namespace {

constexpr double kWidth = 800.0;   // [px]
constexpr double kHeight = 500.0;  // [px]
constexpr double kLeft = 90.0, kRight = 20.0, kTop = 40.0, kBottom = 60.0;  // [px] margins
constexpr double kLegendSwatch = 50.0;     // [px] the legend column's gap, line sample and margins
constexpr double kLegendCharacter = 7.0;   // [px] per character of a label (12 px sans-serif, generous)
const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", value);
  return buffer;
}

/// One axis: data range mapped to a pixel range, linear or log10.
struct Axis {
  bool log = false;
  double low = 0.0, high = 1.0;  // in axis space (log10 of the value for log axes)
  double pixel_low = 0.0, pixel_high = 1.0;

  bool accepts(double v) const { return std::isfinite(v) && (!log || v > 0.0); }
  double space(double v) const { return log ? std::log10(v) : v; }
  double pixel(double v) const { return pixel_low + (space(v) - low) / (high - low) * (pixel_high - pixel_low); }

  /// Sets the range from data (axis space), padded, with a unit range when empty or flat.
  void fit(double data_low, double data_high) {
    if (!(data_low <= data_high)) data_low = 0.0, data_high = 1.0;
    if (log) {  // a twentieth of the span (at least of a decade) beyond the data, as on a linear axis
      const double pad = 0.05 * std::max(data_high - data_low, 1.0);
      low = data_low - pad;
      high = data_high + pad;
      return;
    }
    double span = data_high - data_low;
    if (span <= 0.0) span = std::max(1.0, std::abs(data_high));
    low = data_low - 0.05 * span;
    high = data_high + 0.05 * span;
    if (data_low >= 0.0 && low < 0.0) low = 0.0;  // do not push a non-negative range below zero
  }

  /// Tick positions (values, not axis space).
  std::vector<double> ticks() const {
    std::vector<double> values;
    if (log) {  // the decades inside the range; 1, 2 and 5 times them where fewer than two are
      const int first = static_cast<int>(std::ceil(low - 1e-9)), last = static_cast<int>(std::floor(high + 1e-9));
      if (last - first >= 1) {
        const int step = std::max(1, static_cast<int>(std::ceil((high - low) / 8.0)));
        for (int e = first; e <= last; e += step) values.push_back(std::pow(10.0, e));
        return values;
      }
      for (int e = first - 1; e <= last; ++e)
        for (const double m : {1.0, 2.0, 5.0}) {
          const double v = m * std::pow(10.0, e);
          if (space(v) >= low - 1e-9 && space(v) <= high + 1e-9) values.push_back(v);
        }
      return values;
    }
    const double raw = (high - low) / 6.0;
    const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
    double step = magnitude;
    for (double m : {1.0, 2.0, 5.0, 10.0})
      if (m * magnitude >= raw) {
        step = m * magnitude;
        break;
      }
    for (double v = std::ceil(low / step) * step; v <= high + 1e-9 * step; v += step)
      values.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
    return values;
  }
};

void fit_axes(const Figure& figure, Axis& x_axis, Axis& y_axis) {
  double x_low = std::numeric_limits<double>::infinity(), x_high = -x_low;
  double y_low = x_low, y_high = -x_low;
  for (const Series& s : figure.series)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!x_axis.accepts(s.x[i]) || !y_axis.accepts(s.y[i])) continue;
      x_low = std::min(x_low, x_axis.space(s.x[i]));
      x_high = std::max(x_high, x_axis.space(s.x[i]));
      y_low = std::min(y_low, y_axis.space(s.y[i]));
      y_high = std::max(y_high, y_axis.space(s.y[i]));
    }
  x_axis.fit(x_low, x_high);
  y_axis.fit(y_low, y_high);
}

}  // namespace

void write_svg(const Figure& figure, const std::filesystem::path& path) {
  Axis x_axis{figure.log_x, 0.0, 1.0, kLeft, kWidth - kRight};
  Axis y_axis{figure.log_y, 0.0, 1.0, kHeight - kBottom, kTop};
  fit_axes(figure, x_axis, y_axis);
  // The legend stands right of the plot, never over a line: the figure widens by its column.
  std::size_t longest_label = 0;
  for (const Series& s : figure.series) longest_label = std::max(longest_label, s.label.size());
  const double legend_width = longest_label > 0 ? kLegendSwatch + kLegendCharacter * static_cast<double>(longest_label) : 0.0;
  const double width = kWidth + legend_width;

  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << kHeight
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << kWidth / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" << escape(figure.title)
      << "</text>\n";

  // Grid and tick labels.
  for (double v : x_axis.ticks()) {
    const double px = x_axis.pixel(v);
    svg << "<line x1=\"" << px << "\" y1=\"" << kTop << "\" x2=\"" << px << "\" y2=\"" << kHeight - kBottom
        << "\" stroke=\"#ddd\"/>\n<text x=\"" << px << "\" y=\"" << kHeight - kBottom + 16
        << "\" text-anchor=\"middle\">" << number(v) << "</text>\n";
  }
  for (double v : y_axis.ticks()) {
    const double py = y_axis.pixel(v);
    svg << "<line x1=\"" << kLeft << "\" y1=\"" << py << "\" x2=\"" << kWidth - kRight << "\" y2=\"" << py
        << "\" stroke=\"#ddd\"/>\n<text x=\"" << kLeft - 6 << "\" y=\"" << py + 4 << "\" text-anchor=\"end\">"
        << number(v) << "</text>\n";
  }
  svg << "<rect x=\"" << kLeft << "\" y=\"" << kTop << "\" width=\"" << kWidth - kLeft - kRight << "\" height=\""
      << kHeight - kTop - kBottom << "\" fill=\"none\" stroke=\"black\"/>\n"
      << "<text x=\"" << (kLeft + kWidth - kRight) / 2 << "\" y=\"" << kHeight - 18 << "\" text-anchor=\"middle\">"
      << escape(figure.x_label) << "</text>\n"
      << "<text transform=\"translate(18," << (kTop + kHeight - kBottom) / 2
      << ") rotate(-90)\" text-anchor=\"middle\">" << escape(figure.y_label) << "</text>\n";

  // Series.
  for (std::size_t k = 0; k < figure.series.size(); ++k) {
    const Series& s = figure.series[k];
    const char* colour = kColours[k % (sizeof kColours / sizeof kColours[0])];
    const std::size_t n = std::min(s.x.size(), s.y.size());
    if (s.line) {
      std::ostringstream points;
      std::size_t count = 0;
      auto flush = [&] {
        if (count > 1)
          svg << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"1.5\""
              << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << " points=\"" << points.str() << "\"/>\n";
        points.str("");
        count = 0;
      };
      for (std::size_t i = 0; i < n; ++i) {
        if (!x_axis.accepts(s.x[i]) || !y_axis.accepts(s.y[i])) {
          flush();
          continue;
        }
        points << number(x_axis.pixel(s.x[i])) << ',' << number(y_axis.pixel(s.y[i])) << ' ';
        ++count;
      }
      flush();
    }
    if (s.markers)
      for (std::size_t i = 0; i < n; ++i)
        if (x_axis.accepts(s.x[i]) && y_axis.accepts(s.y[i]))
          svg << "<circle cx=\"" << number(x_axis.pixel(s.x[i])) << "\" cy=\"" << number(y_axis.pixel(s.y[i]))
              << "\" r=\"3.5\" fill=\"" << colour << "\"/>\n";
    if (!s.label.empty()) {
      const double ly = kTop + 12 + 16 * static_cast<double>(k);
      const double lx = kWidth - kRight + 12;
      svg << "<line x1=\"" << lx << "\" y1=\"" << ly - 4 << "\" x2=\"" << lx + 20 << "\" y2=\"" << ly - 4 << "\" stroke=\""
          << colour << "\" stroke-width=\"2\"" << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << "/>\n<text x=\"" << lx + 25
          << "\" y=\"" << ly << "\">" << escape(s.label) << "</text>\n";
    }
  }
  svg << "</svg>\n";

  write_whole_file(path.string(), svg.str());
}

}  // namespace railcrash::plot
