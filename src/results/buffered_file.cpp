#include "railcrash/results/buffered_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "railcrash/core/whole_file.hpp"

// The fast path builds the twelve digits in a 128-bit integer whose lowest byte is the first
// character: it needs unsigned __int128 and a little-endian machine. Elsewhere every number
// goes through std::to_chars (the same text, slower).
#if defined(__SIZEOF_INT128__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define RAILCRASH_FORMAT_FAST_PATH 1
#else
#define RAILCRASH_FORMAT_FAST_PATH 0
#endif

namespace railcrash {

namespace {

#if RAILCRASH_FORMAT_FAST_PATH
__extension__ typedef unsigned __int128 Uint128;  // (__extension__: no -Wpedantic warning for it)

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

constexpr std::uint64_t kPowersOfFive[] = {  // 5^0 .. 5^22 (< 2^52)
    1ULL,           5ULL,           25ULL,           125ULL,           625ULL,           3125ULL,
    15625ULL,       78125ULL,       390625ULL,       1953125ULL,       9765625ULL,       48828125ULL,
    244140625ULL,   1220703125ULL,  6103515625ULL,   30517578125ULL,   152587890625ULL,  762939453125ULL,
    3814697265625ULL, 19073486328125ULL, 95367431640625ULL, 476837158203125ULL, 2384185791015625ULL};

/// The integer nearest to magnitude x 10^shift, decided from magnitude's bits without rounding:
/// magnitude = mantissa 2^e, so magnitude 10^shift = (mantissa 5^shift) 2^(e + shift), and
/// mantissa 5^shift < 2^105 for shift <= 22. False at an exact tie (printf's rule for those is
/// std::to_chars' business), for shift outside 0..22, and where the product is an integer.
bool nearest_integer_exactly(std::uint64_t bits, int shift, std::uint64_t& nearest) {
  if (shift < 0 || shift > 22) return false;
  const std::uint64_t mantissa = (bits & ((1ULL << 52) - 1)) | (1ULL << 52);  // a normal number
  const int binary_exponent = static_cast<int>(bits >> 52) - 1075;            // magnitude = mantissa 2^that
  const Uint128 product = static_cast<Uint128>(mantissa) * kPowersOfFive[shift];
  const int fraction_bits = -(binary_exponent + shift);
  if (fraction_bits <= 0 || fraction_bits >= 127) return false;
  const Uint128 whole = product >> fraction_bits;
  const Uint128 fraction = product - (whole << fraction_bits);
  const Uint128 half = static_cast<Uint128>(1) << (fraction_bits - 1);
  if (fraction == half) return false;
  nearest = static_cast<std::uint64_t>(whole) + (fraction > half ? 1 : 0);  // whole < 1e13 here
  return true;
}

/// The twelve significant digits of magnitude rounded to nearest and its decimal exponent, as
/// printf's "%.12g" has them: false outside 1e-33..1e33 and at exact rounding ties. Double
/// arithmetic decides the rounding except within 1e-3 of a tie (the scaled value's error is
/// below 2.5e-4 of a unit of the twelfth digit); there the exact product decides it
/// (nearest_integer_exactly), where 10^shift has one (magnitudes from 1e-11 up to 1e12).
bool twelve_digits(double magnitude, std::uint64_t& digits, int& exponent) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &magnitude, sizeof bits);
  const int binary_exponent = static_cast<int>(bits >> 52) - 1023;  // magnitude in [2^b, 2^(b+1)): a normal number
  // floor(log10(magnitude)) or one low (then a second attempt below): floor(b log10(2)) as
  // (b 78913) >> 18, exact for |b| < 1650 (78913 / 2^18 = 0.3010300...; >> of a negative int is
  // arithmetic with GCC and Clang, and in C++20).
  exponent = (binary_exponent * 78913) >> 18;
  for (int attempt = 0; attempt < 4; ++attempt) {
    const double scaled = scaled_to_twelve_digits(magnitude, exponent);
    if (scaled < 0.0 || scaled >= 1e13) return false;
    const auto whole = static_cast<std::uint64_t>(scaled);  // floor: scaled >= 0
    const double fraction = scaled - static_cast<double>(whole);  // exact: scaled < 2^53
    digits = whole + (fraction > 0.5 ? 1 : 0);
    if (std::abs(fraction - 0.5) < 1e-3 && !nearest_integer_exactly(bits, 11 - exponent, digits)) return false;
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

/// Sixteen characters in one integer, the first in the lowest byte (the order in which they lie
/// in memory on this byte order).
using Characters16 = Uint128;

Characters16 pair_characters(std::uint32_t pair) {  // "00".."99"
  std::uint16_t characters = 0;
  std::memcpy(&characters, kDigitPairs + 2 * pair, sizeof characters);
  return characters;
}

/// The twelve digits as characters, then four '0's, built in registers: written to memory a
/// byte at a time and read back as words (the trailing-zero count, the 16-byte copies), they
/// would stall the reads (no store forwarding from narrow stores to a wider load).
Characters16 digit_characters(std::uint64_t digits) {
  const auto high = static_cast<std::uint32_t>(digits / 1000000), low = static_cast<std::uint32_t>(digits % 1000000);
  return pair_characters(high / 10000) | pair_characters(high / 100 % 100) << 16 | pair_characters(high % 100) << 32 |
         pair_characters(low / 10000) << 48 | pair_characters(low / 100 % 100) << 64 | pair_characters(low % 100) << 80 |
         static_cast<Characters16>(0x30303030U) << 96;
}

/// The number of trailing '0's among the twelve digits (the first is not '0').
int trailing_zeros(Characters16 characters) {
  const Characters16 not_zero = characters ^ (~static_cast<Characters16>(0) / 255 * '0');  // zero bytes where '0'
  const auto upper = static_cast<std::uint64_t>(not_zero >> 64), lower = static_cast<std::uint64_t>(not_zero);
  const int zero_bytes_on_top = upper != 0 ? __builtin_clzll(upper) / 8 : 8 + __builtin_clzll(lower) / 8;
  return zero_bytes_on_top - 4;  // less the four '0's after the digits
}

void store16(char* at, Characters16 characters) { std::memcpy(at, &characters, sizeof characters); }
#endif  // RAILCRASH_FORMAT_FAST_PATH

}  // namespace

char* format_general12(char* first, double value) {
  const double magnitude = std::abs(value);
  if (magnitude == 0.0) {  // a tenth of a slider-crank run's numbers (bodies at rest, idle friction)
    if (std::signbit(value)) *first++ = '-';
    *first++ = '0';
    return first;
  }
#if RAILCRASH_FORMAT_FAST_PATH
  std::uint64_t digits = 0;
  int exponent = 0;
  if (magnitude >= 1e-33 && magnitude <= 1e33 && twelve_digits(magnitude, digits, exponent)) {
    // Each case writes whole 16-byte blocks (at most 30 bytes from first) and then moves the end
    // to the last character it means: no loop whose length changes from one number to the next.
    const Characters16 text = digit_characters(digits);
    const int significant = 12 - trailing_zeros(text);
    char* out = first;
    *out = '-';
    out += value < 0.0 ? 1 : 0;
    if (exponent < -4 || exponent >= 12) {  // d.ddde+XX
      *out++ = static_cast<char>(text);
      if (significant > 1) {
        *out++ = '.';
        store16(out, text >> 8);
        out += significant - 1;
      }
      *out++ = 'e';
      *out++ = exponent < 0 ? '-' : '+';
      const int power = std::abs(exponent);  // <= 33
      *out++ = static_cast<char>('0' + power / 10);
      *out++ = static_cast<char>('0' + power % 10);
    } else if (exponent >= 0) {  // ddd.ddd: exponent + 1 digits before the point
      const int whole_digits = exponent + 1;
      store16(out, text);
      store16(out + whole_digits + 1, text >> (8 * whole_digits));  // the fraction, one place on
      out[whole_digits] = '.';
      out += significant > whole_digits ? significant + 1 : whole_digits;
    } else {  // 0.000ddd: -exponent - 1 zeros after the point
      std::memcpy(out, "0.000000", 8);
      store16(out + 1 - exponent, text);
      out += 1 - exponent + significant;
    }
    return out;
  }
#endif
  return std::to_chars(first, first + 32, value, std::chars_format::general, 12).ptr;
}

BufferedFile::BufferedFile(const std::string& path) {
  // O_NOFOLLOW: a symbolic link planted under a result file's name is refused (ELOOP), not
  // written through.
  descriptor_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0666);
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
  std::size_t taken = 0;
  error_ = write_all(descriptor_, buffer_.get(), used_, &taken);  // (whole_file.hpp: the one checked write loop)
  written_ += taken;  // also the part of a failed write the OS took
  used_ = 0;
}

bool BufferedFile::flush() {
  write_out();
  return error_ == 0;
}

}  // namespace railcrash
