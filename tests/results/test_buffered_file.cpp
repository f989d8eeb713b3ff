// The CSV writer (results/buffered_file.hpp): printf's "%.12g" text from format_general12 (also
// summary.json's, json_number), and a failed write kept with the OS's reason.
#include <catch2/catch.hpp>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "railcrash/results/buffered_file.hpp"
#include "railcrash/results/results.hpp"
#include "support.hpp"

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
  // Where format_general12 leaves its fast path or changes the exponent: rounding ties and near
  // ties of the twelfth digit, carries into a thirteenth, powers of ten and their neighbours,
  // the ends of its range (1e-33, 1e33), decimal grids (output times) and integers.
  for (const double tie : {1.000000000005, 2.5, 0.125, 1234567890125.0, 1234567890135.0, 9.999999999995, 999999999999.5,
                           99999999999.95, 0.99999999999949, 0.9999999999995, 0.99999999999951, 1.0000000000049999})
    for (const double value : {tie, -tie, std::nextafter(tie, 0.0), std::nextafter(tie, 1e300)}) values.push_back(value);
  for (int power = -40; power <= 40; ++power)
    for (const double value : {std::pow(10.0, power), std::nextafter(std::pow(10.0, power), 0.0),
                               std::nextafter(std::pow(10.0, power), 1e300), 9.99999999999 * std::pow(10.0, power)})
      values.push_back(value);
  // Near ties of the twelfth digit at every decade: within 1e-3 of a tie the exact product
  // decides (nearest_integer_exactly, 1e-11 up to 1e12), elsewhere std::to_chars.
  std::uniform_int_distribution<std::int64_t> twelve_digits(100000000000, 999999999999);
  std::uniform_int_distribution<int> decade(-40, 40);
  for (int k = 0; k < 20000; ++k) {
    const double tie = (static_cast<double>(twelve_digits(random)) + 0.5) * std::pow(10.0, decade(random));
    for (const double value : {tie, std::nextafter(tie, 0.0), std::nextafter(tie, 1e300), -tie}) values.push_back(value);
  }
  for (int k = 0; k <= 3000; ++k) values.push_back(k * 1e-3);
  for (int k = 0; k <= 1000; ++k) values.push_back(static_cast<double>(k) * 1e-5 + 1e-5 * std::floor(k / 7));
  std::uniform_int_distribution<std::int64_t> integer(-10000000000000, 10000000000000);
  for (int k = 0; k < 1000; ++k) values.push_back(static_cast<double>(integer(random)));
  // Random bit patterns over the whole range of finite doubles.
  std::uniform_int_distribution<std::uint64_t> bits(0, 0x7FEFFFFFFFFFFFFFULL);
  for (int k = 0; k < 10000; ++k) {
    const std::uint64_t pattern = bits(random);
    double value = 0.0;
    std::memcpy(&value, &pattern, sizeof value);
    values.push_back(k % 2 ? value : -value);
  }
  const std::string path = (railcrash::testing::temp_path("railcrash_test_buffered_file.csv")).string();
  std::string expected;
  int json_differs = 0;  // summary.json's numbers (json_number) are the same text, null where not finite
  {
    BufferedFile file(path);
    REQUIRE(file.is_open());
    for (const double value : values) {
      char text[40];
      std::snprintf(text, sizeof text, "%.12g", value);
      expected += std::string(text) + ",";
      if (railcrash::json_number(value) != (std::isfinite(value) ? std::string(text) : "null")) ++json_differs;
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
  CHECK(written.str() == expected);  // also more than one buffer's worth
  CHECK(json_differs == 0);
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
