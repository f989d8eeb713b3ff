// How `railcrash report` reads the files of a run or study folder (issue 36): regular files
// only, without following a symbolic link, and within a size limit, so that a FIFO named
// summary.json cannot block the report and a link to /dev/zero cannot fill its memory.
//
// - A FIFO, socket or device under a result file's name is refused (it is opened with
//   O_NONBLOCK, so opening a FIFO does not wait for a writer, and never read).
// - A symbolic link is refused, as the writers refuse to write through one (O_NOFOLLOW).
// - JSON files (summary.json, model.json) above kMaxJsonBytes are refused: railcrash writes
//   them well under a few megabytes even for thousands of bodies with names at the loader's
//   length limit (model_io.hpp kMaxNameLength).
// - Tables and the other files (CSV, Markdown, SVG) above max_table_bytes() are refused: the
//   report holds a CSV file's text and each of its values as an 8-byte double (up to four
//   times the text: "0," is two bytes), so a file of an eighth of the machine's memory needs
//   up to five eighths of it.
// Each refusal is an InputError naming the file, its size or kind, the limit and what to do.
#pragma once

#include <cstdint>
#include <string>

namespace railcrash::report {

constexpr std::uint64_t kMaxJsonBytes = std::uint64_t{64} << 20;  // [bytes] 64 MiB

/// An eighth of the physical memory (sysconf), at least 64 MiB. [bytes]
std::uint64_t max_table_bytes();

struct FolderFile {
  bool found = false;  // false: no file of that name (the text is empty)
  std::string text;
};

/// Reads the regular file at path whole. No file: found false. A link, a FIFO or another
/// file that is not regular, a file above `limit` bytes or one that cannot be read: InputError
/// ("'out/summary.json' is 80.0 MB, more than the report's limit of 64.0 MB for a JSON file: "
/// + advice).
FolderFile read_folder_file(const std::string& path, std::uint64_t limit, const std::string& advice);

/// The first `bytes` bytes (fewer if the file is shorter) of a file read_folder_file accepts
/// (the same checks except the size limit). No file: found false.
FolderFile read_folder_file_head(const std::string& path, std::size_t bytes);

}  // namespace railcrash::report
