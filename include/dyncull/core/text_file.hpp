/// @file text_file.hpp
/// Bounded, streaming access to the files dyncull's readers take (TUM trajectories and image lists,
/// camera.txt, YOLO labels, detection JSON, YOLO models): one file-opening rule for all of them. Regular
/// files only, checked again on the opened descriptor; files of the kernel's (/proc, /sys, /dev, procfs
/// or sysfs anywhere) refused by name and by file system; an open that never waits; a size cap per kind
/// of file; then one line at a time under a length and a line-count limit. A directory, a FIFO,
/// /dev/zero, /proc/self/pagemap or a huge file gets a reason instead of a blocked or unbounded read.
/// No paper equation.
///
/// API:
///   text::LineReader in;
///   if (!in.open(path)) return fail(in.error());             // "path: is a FIFO, not a regular file"
///   std::string_view line;
///   for (text::LineStatus s; (s = in.next(&line)) != text::LineStatus::End;) {
///     if (s == text::LineStatus::Line) ...                     // in.line_number() is 1-based
///     else if (s == text::LineStatus::TooLong) ...             // `line` holds the first max_line_chars bytes
///     else return fail(in.error());                           // TooManyLines or ReadError, reason set
///   }
///   std::string json; text::read_small_file(path, max_bytes, &json, &why);  // whole file, bounded
///   text::InputFile f; f.open(path, max_bytes, &why); f.read(buffer, n);    // raw bytes, same rule
#pragma once

#include "dyncull/core/text.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#if defined(__unix__) || defined(__APPLE__)
#define DYNCULL_POSIX_FILES 1
#include <cerrno>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#if defined(__linux__)
#include <sys/vfs.h>
#endif
#else
#define DYNCULL_POSIX_FILES 0
#endif

namespace dyncull::text {

/// Size caps by kind of file, in bytes: far above any real file of the kind, far below what a wrong
/// path could feed a reader. Each reader passes its own (YOLO models: opencv/yolo_detector.hpp).
constexpr std::uint64_t kMaxListFileBytes = std::uint64_t(1) << 30;   ///< trajectories, image lists, YOLO labels
constexpr std::uint64_t kMaxCameraFileBytes = std::uint64_t(1) << 16;  ///< camera.txt: a dozen "key value" lines

/// Why `path` cannot be read as a text file, or "" when it is a regular file (symbolic links are
/// followed). The reason names the path (escaped, see quote_path) and what it is instead: a directory,
/// a FIFO, a device, a socket, missing, or a file of the kernel's (procfs, sysfs, /dev), whose size says
/// nothing about what a read returns. Only the file's status and name are read, so this never blocks.
inline std::string regular_file_problem(const std::string& path) {
  const std::string shown = quote_path(path);
  // The system reads a name only up to its first NUL: such a path would open another file.
  if (path.find('\0') != std::string::npos) return shown + ": contains a NUL byte, which no file name can";
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  using std::filesystem::file_type;
  switch (st.type()) {
    case file_type::regular: break;
    case file_type::not_found: return shown + ": no such file";
    case file_type::directory: return shown + ": is a directory, not a regular file";
    case file_type::fifo: return shown + ": is a FIFO (named pipe), not a regular file";
    case file_type::character: return shown + ": is a character device, not a regular file";
    case file_type::block: return shown + ": is a block device, not a regular file";
    case file_type::socket: return shown + ": is a socket, not a regular file";
    default:
      return shown + ": cannot be read" + (ec ? " (" + ec.message() + ")" : std::string(", not a regular file"));
  }
  // By name, after links: /proc/self/pagemap streams gigabytes and /proc/kmsg blocks, both "regular".
  const std::filesystem::path real = std::filesystem::canonical(path, ec);
  if (ec) return shown + ": cannot be read (" + ec.message() + ")";
  const std::string name = real.generic_string();
  for (const char* root : {"/proc", "/sys", "/dev"}) {
    const std::size_t n = std::strlen(root);
    if (name.compare(0, n, root) == 0 && (name.size() == n || name[n] == '/'))
      return shown + ": is a file of the kernel's (under " + root + "), not a regular file";
  }
  return {};
}

/// A regular file open for reading, checked on the opened descriptor: whatever the path names by the
/// time it is opened (a link swapped for a FIFO, a procfs mount elsewhere), a file that is not regular or
/// is over its size cap is refused, and the open itself never waits (POSIX: O_NONBLOCK). read() stops
/// after max_bytes + 1 bytes, so a file that grows while it is read is noticed, not followed.
class InputFile {
 public:
  InputFile() = default;
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;
  ~InputFile() { close(); }

  /// False with `*error` = "path: why" (the path escaped by quote_path) when regular_file_problem finds
  /// one, the file cannot be opened, is not regular once open, or is over `max_bytes` (its size named).
  bool open(const std::string& path, std::uint64_t max_bytes, std::string* error) {
    close();
    *error = regular_file_problem(path);
    if (!error->empty()) return false;
    const std::string shown = quote_path(path);
    max_bytes_ = max_bytes;
    read_bytes_ = 0;
#if DYNCULL_POSIX_FILES
    fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd_ < 0) {
      *error = shown + ": cannot open for reading (" + std::strerror(errno) + ")";
      return false;
    }
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode) || kernel_file(fd_)) {
      *error = shown + ": is not a regular file once open";
      close();
      return false;
    }
    size_ = static_cast<std::uint64_t>(st.st_size);
#else
    file_.open(path, std::ios::in | std::ios::binary);
    std::error_code ec;
    size_ = static_cast<std::uint64_t>(std::filesystem::file_size(path, ec));
    if (!file_ || ec) {
      *error = shown + ": cannot open for reading";
      close();
      return false;
    }
#endif
    if (size_ > max_bytes) {
      *error = shown + ": " + std::to_string(size_) + " bytes, over the limit of " + std::to_string(max_bytes);
      close();
      return false;
    }
    return true;
  }

  /// Up to `n` bytes into `buffer`: the count, 0 at the end of the file, -1 on a read error, -2 once more
  /// than max_bytes were read (the file grew past its cap).
  long read(char* buffer, std::size_t n) {
    if (!is_open()) return 0;
    const std::uint64_t room = max_bytes_ - read_bytes_;  // read_bytes_ <= max_bytes_: past it read() stopped
    if (room < n) n = static_cast<std::size_t>(room) + 1;  // one byte more than the cap shows it was passed
#if DYNCULL_POSIX_FILES
    ssize_t got = -1;
    do got = ::read(fd_, buffer, n);
    while (got < 0 && errno == EINTR);
    if (got < 0) return -1;
#else
    file_.read(buffer, static_cast<std::streamsize>(n));
    const std::streamsize got = file_.gcount();
    if (got == 0 && file_.bad()) return -1;
#endif
    read_bytes_ += static_cast<std::uint64_t>(got);
    if (read_bytes_ > max_bytes_) {
      close();
      return -2;
    }
    return static_cast<long>(got);
  }

  bool is_open() const {
#if DYNCULL_POSIX_FILES
    return fd_ >= 0;
#else
    return file_.is_open();
#endif
  }
  /// The size the opened file had.
  std::uint64_t size() const { return size_; }
  void close() {
#if DYNCULL_POSIX_FILES
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
#else
    file_.close();
    file_.clear();
#endif
  }

 private:
#if DYNCULL_POSIX_FILES
  /// procfs and sysfs on the opened descriptor: they may be mounted outside /proc and /sys.
  static bool kernel_file(int fd) {
#if defined(__linux__)
    struct statfs fs {};
    if (::fstatfs(fd, &fs) != 0) return true;
    constexpr long kProcfs = 0x9fa0, kSysfs = 0x62656572, kDebugfs = 0x64626720, kTracefs = 0x74726163;
    const long type = static_cast<long>(fs.f_type);
    return type == kProcfs || type == kSysfs || type == kDebugfs || type == kTracefs;
#else
    (void)fd;
    return false;
#endif
  }
  int fd_ = -1;
#else
  std::ifstream file_;
#endif
  std::uint64_t size_ = 0;
  std::uint64_t max_bytes_ = 0;
  std::uint64_t read_bytes_ = 0;
};

/// Limits of a LineReader. Each reader picks a line count that bounds the memory of what it keeps.
struct LineReaderOptions {
  std::size_t max_line_chars = kMaxLineChars;  ///< longer lines come back as TooLong, cut to this
  std::size_t max_lines = 1000000;             ///< lines (blank and comments included) before TooManyLines
  std::uint64_t max_bytes = kMaxListFileBytes;  ///< a larger file is refused at open()
};

/// What LineReader::next() found.
enum class LineStatus : std::uint8_t {
  Line = 0,      ///< a line, without its newline (a carriage return before it is kept)
  TooLong,       ///< a line over max_line_chars: its first max_line_chars bytes; line_chars() has the length
  End,           ///< no more lines
  TooManyLines,  ///< the line after max_lines; error() says so, reading stops
  ReadError,     ///< the file could not be read; error() says so, reading stops
};

/// Reads a regular file line by line in memory bounded by max_line_chars plus a 64 KiB buffer,
/// whatever the file holds. The last line needs no newline. Not copyable (it owns the stream).
class LineReader {
 public:
  LineReader() = default;
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  /// Opens `path`; false with error() = "path: why" when InputFile::open refuses it (not a regular file,
  /// a file of the kernel's, over options.max_bytes) or it cannot be opened. Error texts name the path
  /// escaped by quote_path.
  bool open(const std::string& path, const LineReaderOptions& options = {}) {
    options_ = options;
    path_ = quote_path(path);
    error_.clear();
    line_number_ = 0;
    line_chars_ = 0;
    pos_ = len_ = 0;
    done_ = false;
    if (!file_.open(path, options.max_bytes, &error_)) {
      done_ = true;
      return false;
    }
    buffer_.resize(kChunk);
    return true;
  }

  /// The next line into `*line` (valid until the next call). See LineStatus.
  LineStatus next(std::string_view* line) {
    *line = std::string_view();
    if (done_) return LineStatus::End;
    line_.clear();
    line_chars_ = 0;
    bool any = false;
    while (true) {
      if (pos_ == len_ && !fill()) {
        if (!error_.empty()) return LineStatus::ReadError;
        done_ = true;
        if (!any) return LineStatus::End;
        break;
      }
      any = true;
      const char* begin = buffer_.data() + pos_;
      const std::size_t available = len_ - pos_;
      const void* nl = std::memchr(begin, '\n', available);
      const std::size_t take = nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - begin) : available;
      if (line_.size() < options_.max_line_chars)
        line_.append(begin, std::min(take, options_.max_line_chars - line_.size()));
      line_chars_ += take;
      pos_ += take;
      if (nl) {
        ++pos_;  // the '\n'
        break;
      }
    }
    if (line_number_ >= options_.max_lines) {
      error_ = path_ + ": more than " + std::to_string(options_.max_lines) + " lines";
      done_ = true;
      return LineStatus::TooManyLines;
    }
    ++line_number_;
    *line = line_;
    return line_chars_ > options_.max_line_chars ? LineStatus::TooLong : LineStatus::Line;
  }

  /// 1-based number of the line next() returned last.
  std::size_t line_number() const { return line_number_; }
  /// Full length in bytes of the line next() returned last (more than its text when TooLong).
  std::size_t line_chars() const { return line_chars_; }
  /// "path: why" after a failed open(), TooManyLines or ReadError; "" otherwise.
  const std::string& error() const { return error_; }
  /// The path as reasons show it (quote_path).
  const std::string& path() const { return path_; }

 private:
  static constexpr std::size_t kChunk = std::size_t(1) << 16;

  bool fill() {
    if (!file_.is_open()) return false;
    const long got = file_.read(buffer_.data(), buffer_.size());
    pos_ = 0;
    len_ = got > 0 ? static_cast<std::size_t>(got) : 0;
    if (got > 0) return true;
    if (got == -1) error_ = path_ + ": read error";
    if (got == -2) error_ = path_ + ": grew past the limit of " + std::to_string(options_.max_bytes) + " bytes";
    file_.close();
    return false;
  }

  LineReaderOptions options_;
  InputFile file_;
  std::vector<char> buffer_;
  std::size_t pos_ = 0, len_ = 0;
  std::string line_;
  std::string path_;
  std::string error_;
  std::size_t line_number_ = 0;
  std::size_t line_chars_ = 0;
  bool done_ = true;
};

/// "path:line: " for a reason about the line a LineReader returned last.
inline std::string line_location(const LineReader& in) {
  return in.path() + ":" + std::to_string(in.line_number()) + ": ";
}

/// Reads a whole regular file of at most `max_bytes` into `*text`; false with `*error` = "path: why"
/// for what InputFile::open refuses (not a regular file, a file of the kernel's, larger: its size is
/// named) or cannot be read. Never reads more than max_bytes + 1 bytes.
inline bool read_small_file(const std::string& path, std::size_t max_bytes, std::string* text, std::string* error) {
  text->clear();
  InputFile file;
  if (!file.open(path, max_bytes, error)) return false;
  text->reserve(static_cast<std::size_t>(file.size()));
  char chunk[1 << 14];
  for (long got; (got = file.read(chunk, sizeof chunk)) != 0;) {
    if (got < 0) {
      *error = quote_path(path) + (got == -1 ? std::string(": read error")
                                              : ": more than " + std::to_string(max_bytes) + " bytes, over the limit of " +
                                                    std::to_string(max_bytes));
      text->clear();
      return false;
    }
    text->append(chunk, static_cast<std::size_t>(got));
  }
  return true;
}

}  // namespace dyncull::text
