// The CSV writer (results/buffered_file.hpp): printf's "%.12g" text from std::to_chars, and a
// failed write kept with the OS's reason.
#include <catch2/catch.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "railcrash/results/buffered_file.hpp"

using railcrash::BufferedFile;

TEST_CASE("numbers are written as printf's %.12g, byte for byte", "[results]") {
  std::vector<double> values{0.0, -0.0, 1.0, -1.0, 0.1, 1.0 / 3.0, 123456789012.0, 1234567890123.0, 1e-5, 1e-4,
                             1e21, 5e-324, std::numeric_limits<double>::max(), -2.5e-308, 457.6, 1.67e6,
                             std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                             std::numeric_limits<double>::quiet_NaN()};
  std::mt19937_64 random(14);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-30, 30);
  for (int k = 0; k < 10000; ++k) values.push_back(mantissa(random) * std::pow(10.0, exponent(random)));
  const std::string path = (std::filesystem::temp_directory_path() / "railcrash_test_buffered_file.csv").string();
  std::string expected;
  {
    BufferedFile file(path);
    REQUIRE(file.is_open());
    for (const double value : values) {
      char text[40];
      std::snprintf(text, sizeof text, "%.12g", value);
      expected += std::string(text) + ",";
      file.number(value);
      file.character(',');
    }
    file.text("end\n");
    expected += "end\n";
    CHECK(file.flush());
    CHECK(file.error() == 0);
  }
  std::ifstream in(path);
  std::stringstream written;
  written << in.rdbuf();
  CHECK(written.str() == expected);  // also more than one buffer's worth: ~170 kB
  CHECK(expected.size() > BufferedFile::kCapacity);
  std::filesystem::remove(path);
}

TEST_CASE("a full device makes the writer keep ENOSPC and write nothing more", "[results][faults]") {
  if (!std::filesystem::exists("/dev/full")) return;  // no device that is always full here
  BufferedFile file("/dev/full");
  REQUIRE(file.is_open());
  file.text("t,x\n");
  CHECK(file.error() == 0);  // still in the buffer
  CHECK_FALSE(file.flush());
  CHECK(file.error() == ENOSPC);
  BufferedFile missing("/nonexistent-folder/timeseries.csv");
  CHECK_FALSE(missing.is_open());
  CHECK(missing.error() == ENOENT);
}
