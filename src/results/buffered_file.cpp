#include "railcrash/results/buffered_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace railcrash {

namespace {

constexpr double kPowersOfTen[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                   1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};  // exact

constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

/// magnitude x 10^(11 - exponent) in at most two roundings (relative error <= 2^-52), or -1
/// outside the exponents whose powers of ten are exact.
double scaled_to_twelve_digits(double magnitude, int exponent) {
  const int shift = 11 - exponent;
  if (shift >= 0 && shift <= 22) return magnitude * kPowersOfTen[shift];
  if (shift > 22 && shift <= 44) return magnitude * 1e22 * kPowersOfTen[shift - 22];
  if (shift < 0 && shift >= -22) return magnitude / kPowersOfTen[-shift];
  return -1.0;
}

/// The twelve significant digits of magnitude rounded to nearest and its decimal exponent, as
/// printf's "%.12g" has them, when double arithmetic decides the rounding for certain: false
/// when the scaled value lies within 1e-3 of a rounding tie (its error is below 2.5e-4 of a
/// unit of the twelfth digit) or outside 1e-33..1e33.
bool twelve_digits(double magnitude, std::uint64_t& digits, int& exponent) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &magnitude, sizeof bits);
  const int binary_exponent = static_cast<int>(bits >> 52) - 1023;  // magnitude in [2^b, 2^(b+1)): a normal number
  // floor(b log10(2)) (exact or one low) without a floating floor: b > -120 here
  exponent = (binary_exponent + 120) * 1233 / 4096 - 37;  // 1233 / 4096 = 0.30102..., 120 * 1233 / 4096 = 36.1
  for (int attempt = 0; attempt < 4; ++attempt) {
    const double scaled = scaled_to_twelve_digits(magnitude, exponent);
    if (scaled < 0.0 || scaled >= 1e13) return false;
    const auto whole = static_cast<std::uint64_t>(scaled);  // floor: scaled >= 0
    const double fraction = scaled - static_cast<double>(whole);  // exact: scaled < 2^53
    if (std::abs(fraction - 0.5) < 1e-3) return false;
    digits = whole + (fraction > 0.5 ? 1 : 0);
    if (digits >= 1000000000000ULL) {
      ++exponent;  // the estimate was one low, or the rounding carried into a thirteenth digit
    } else if (digits < 100000000000ULL) {
      --exponent;
    } else {
      return true;
    }
  }
  return false;
}

}  // namespace

char* format_general12(char* first, double value) {
  std::uint64_t digits = 0;
  int exponent = 0;
  const double magnitude = std::abs(value);
  if (magnitude == 0.0) {  // a tenth of a slider-crank run's numbers (bodies at rest, idle friction)
    if (std::signbit(value)) *first++ = '-';
    *first++ = '0';
    return first;
  }
  if (!(magnitude >= 1e-33 && magnitude <= 1e33) || !twelve_digits(magnitude, digits, exponent))
    return std::to_chars(first, first + 32, value, std::chars_format::general, 12).ptr;
  char text[12];  // the twelve digits, most significant first
  auto high = static_cast<std::uint32_t>(digits / 1000000), low = static_cast<std::uint32_t>(digits % 1000000);
  for (int k = 4; k >= 0; k -= 2) {
    const std::size_t high_pair = 2 * (high % 100), low_pair = 2 * (low % 100);
    high /= 100;
    low /= 100;
    text[k] = kDigitPairs[high_pair];
    text[k + 1] = kDigitPairs[high_pair + 1];
    text[k + 6] = kDigitPairs[low_pair];
    text[k + 7] = kDigitPairs[low_pair + 1];
  }
  int significant = 12;
  while (significant > 1 && text[significant - 1] == '0') --significant;
  char* out = first;
  if (value < 0.0) *out++ = '-';
  const auto copy = [&](int from, int to) {
    for (int k = from; k < to; ++k) *out++ = text[k];
  };
  if (exponent < -4 || exponent >= 12) {  // d.ddde+XX
    *out++ = text[0];
    if (significant > 1) {
      *out++ = '.';
      copy(1, significant);
    }
    *out++ = 'e';
    *out++ = exponent < 0 ? '-' : '+';
    const int power = std::abs(exponent);  // <= 33
    *out++ = static_cast<char>('0' + power / 10);
    *out++ = static_cast<char>('0' + power % 10);
  } else if (exponent >= 0) {  // ddd.ddd
    copy(0, exponent + 1);
    if (significant > exponent + 1) {
      *out++ = '.';
      copy(exponent + 1, significant);
    }
  } else {  // 0.000ddd
    *out++ = '0';
    *out++ = '.';
    for (int k = -1; k > exponent; --k) *out++ = '0';
    copy(0, significant);
  }
  return out;
}

BufferedFile::BufferedFile(const std::string& path) {
  descriptor_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (descriptor_ < 0) error_ = errno;
  buffer_.reset(new char[kCapacity]);  // not zeroed (std::make_unique would): only written bytes are read
}

BufferedFile::~BufferedFile() {
  if (descriptor_ < 0) return;
  write_out();
  ::close(descriptor_);
}

void BufferedFile::text(std::string_view text) {
  while (!text.empty()) {
    if (used_ == kCapacity) write_out();
    const std::size_t count = std::min(text.size(), kCapacity - used_);
    std::memcpy(buffer_.get() + used_, text.data(), count);
    used_ += count;
    text.remove_prefix(count);
  }
}

void BufferedFile::number(double value) {
  constexpr std::size_t kLongest = 32;  // "%.12g": sign, 12 digits, point, exponent
  if (used_ + kLongest > kCapacity) write_out();
  used_ = static_cast<std::size_t>(format_general12(buffer_.get() + used_, value) - buffer_.get());
}

void BufferedFile::write_out() {
  if (error_ != 0 || descriptor_ < 0) {  // nothing more after a failure
    used_ = 0;
    return;
  }
  std::size_t written = 0;
  while (written < used_) {
    const ssize_t count = ::write(descriptor_, buffer_.get() + written, used_ - written);
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) {
      error_ = count < 0 ? errno : EIO;
      break;
    }
    written += static_cast<std::size_t>(count);
  }
  used_ = 0;
}

bool BufferedFile::flush() {
  write_out();
  return error_ == 0;
}

}  // namespace railcrash
