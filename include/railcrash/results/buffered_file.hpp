// A text file written through a large buffer by write(2), without iostreams or stdio: the run
// folder's CSV files (timeseries, events, accelerations). Numbers are formatted by
// format_general12 exactly as printf's "%.12g" (the files stay byte-identical to the stdio ones).
// Every write is checked: the first failure's errno (ENOSPC, EIO, ...) is kept and reported
// by error(); after it nothing more is written.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace railcrash {

/// Writes value at first as printf's "%.12g" and returns the end. first must have room for 32
/// characters: the text is at most 32 long, and the bytes up to first + 32 may be written past
/// the end returned. Twelve digits from one scaling by a power of ten where that decides the
/// rounding for certain (faster than std::to_chars with a precision); near a rounding tie the
/// exact product for magnitudes from 1e-11 up to 1e12; std::to_chars elsewhere (exact ties,
/// near-ties outside that range, beyond 1e+-33, infinities and NaN).
char* format_general12(char* first, double value);

class BufferedFile {
 public:
  /// Bytes collected before they go to the file: large enough that writing costs a system call
  /// per some hundred rows, small enough that a full disk is found within the first second
  /// of a run with millisecond rows.
  static constexpr std::size_t kCapacity = 64 * 1024;

  /// Opens (creates or truncates) path; is_open() says whether it could, error() why not.
  explicit BufferedFile(const std::string& path);
  ~BufferedFile();  // writes what is left and closes
  BufferedFile(const BufferedFile&) = delete;
  BufferedFile& operator=(const BufferedFile&) = delete;

  bool is_open() const { return descriptor_ >= 0; }
  void text(std::string_view text);
  void character(char c) {
    if (used_ + 1 > kCapacity) write_out();
    buffer_[used_++] = c;
  }
  /// value as printf's "%.12g".
  void number(double value);
  /// Hands the buffer to the OS; false (and error() set) on a failed write.
  bool flush();
  /// errno of the failed open or the first failed write, 0 while all went well.
  int error() const { return error_; }
  /// Bytes the OS took, from the start of the file (also the part of a failed write it took).
  std::uint64_t written() const { return written_; }
  /// Bytes given to the file so far: written() and those still in the buffer.
  std::uint64_t appended() const { return written_ + used_; }

 private:
  void write_out();

  int descriptor_ = -1;
  std::unique_ptr<char[]> buffer_;  // kCapacity bytes
  std::size_t used_ = 0;            // bytes of buffer_ not written yet
  int error_ = 0;
  std::uint64_t written_ = 0;
};

}  // namespace railcrash
