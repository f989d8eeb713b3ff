#include "railcrash/results/buffered_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>

namespace railcrash {

BufferedFile::BufferedFile(const std::string& path) {
  descriptor_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (descriptor_ < 0) error_ = errno;
  buffer_ = std::make_unique<char[]>(kCapacity);
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
  char* first = buffer_.get() + used_;
  const std::to_chars_result result = std::to_chars(first, first + kLongest, value, std::chars_format::general, 12);
  used_ = static_cast<std::size_t>(result.ptr - buffer_.get());
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
