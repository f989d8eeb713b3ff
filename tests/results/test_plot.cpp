// The SVG writer: lines break at non-finite points, log axes skip non-positive values,
// and points land where the axis mapping puts them.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "railcrash/results/plot.hpp"
#include "support.hpp"

using namespace railcrash;

namespace {

std::string write_and_read(const plot::Figure& figure, const std::string& name) {
  const auto path = testing::temp_path(name);
  plot::write_svg(figure, path);
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  std::filesystem::remove(path);
  return text.str();
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("plot: a NaN breaks a line in two and labels are escaped", "[plot]") {
  plot::Figure figure;
  figure.title = "force <lbf> & stroke";
  figure.series.push_back({"a", {0, 1, 2, 3, 4, 5}, {0, 1, std::nan(""), 3, 4, 5}});
  const std::string svg = write_and_read(figure, "railcrash_plot_nan.svg");
  CHECK(count(svg, "<polyline") == 2);
  CHECK(svg.find("force &lt;lbf&gt; &amp; stroke") != std::string::npos);
  CHECK(svg.find("<svg") == 0);
}

TEST_CASE("plot: log axes skip non-positive points and place decades evenly", "[plot]") {
  plot::Figure figure;
  figure.log_x = figure.log_y = true;
  plot::Series s{"err", {1e-3, 1e-2, 1e-1, 0.0}, {1.0, 1e-1, 1e-2, 5.0}};
  s.markers = true;
  figure.series.push_back(s);
  const std::string svg = write_and_read(figure, "railcrash_plot_log.svg");
  CHECK(count(svg, "<circle") == 3);
  // x axis spans the decades 1e-3..1e-1 over pixels 90..780: the three points sit at 90, 435, 780.
  std::smatch m;
  std::vector<double> cx;
  std::string rest = svg;
  const std::regex circle("cx=\"([0-9.]+)\"");
  while (std::regex_search(rest, m, circle)) {
    cx.push_back(std::stod(m[1]));
    rest = m.suffix();
  }
  REQUIRE(cx.size() == 3);
  // The x axis spans 1e-3..1e-1 and a twentieth of those two decades beyond, over pixels
  // 90..780: the decades are 690 / 2.2 px apart, the middle one at the centre, none on the frame.
  CHECK(cx[1] - cx[0] == Approx(690.0 / 2.2).margin(0.1));  // (coordinates are written to 4 digits)
  CHECK(cx[2] - cx[1] == Approx(690.0 / 2.2).margin(0.1));
  CHECK(cx[1] == Approx(435.0).margin(0.01));
  CHECK(cx[0] > 90.0 + 30.0);
  CHECK(cx[2] < 780.0 - 30.0);
}

TEST_CASE("plot: the legend stands right of the plot and a level line on a decade stays off the frame", "[plot]") {
  // converge.svg's case: error levels 1e-2 .. 1e-4 drawn as dashed lines, the 1 % one the
  // largest value of the figure; the legend once covered the lines' right ends.
  plot::Figure figure;
  figure.log_x = figure.log_y = true;
  plot::Series run{"explicit Euler (dt halved)", {1.0, 2.0, 4.0}, {1e-5, 2e-5, 7e-6}};
  run.markers = true;
  figure.series.push_back(run);
  for (const double level : {1e-2, 1e-3, 1e-4}) {
    plot::Series line{"level", {1.0, 4.0}, {level, level}};
    line.dashed = true;
    figure.series.push_back(line);
  }
  const std::string svg = write_and_read(figure, "railcrash_plot_legend.svg");
  std::smatch m;
  REQUIRE(std::regex_search(svg, m, std::regex("<svg [^>]*width=\"([0-9.]+)\"")));
  CHECK(std::stod(m[1]) > 800.0);  // widened by the legend's column
  // Every legend label starts right of the plot's frame (x = 780).
  std::string rest = svg;
  int labels = 0;
  while (std::regex_search(rest, m, std::regex("<text x=\"([0-9.]+)\" y=\"[0-9.]+\">(explicit Euler|level)"))) {
    CHECK(std::stod(m[1]) > 780.0);
    ++labels;
    rest = m.suffix();
  }
  CHECK(labels == 4);
  // The 1 % line (the largest y) lies below the frame's top edge (y = 40).
  REQUIRE(std::regex_search(svg, m, std::regex("stroke-dasharray=\"6,4\" points=\"[0-9.]+,([0-9.]+) ")));
  CHECK(std::stod(m[1]) > 40.0 + 5.0);
}

TEST_CASE("plot: an unwritable path is an error, not a silent loss", "[plot]") {
  plot::Figure figure;
  CHECK_THROWS_AS(plot::write_svg(figure, "/nonexistent-dir/x.svg"), std::runtime_error);
}
