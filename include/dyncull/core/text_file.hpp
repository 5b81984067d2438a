/// @file text_file.hpp
/// Bounded, streaming access to the text files dyncull's readers take (TUM trajectories and image
/// lists, YOLO labels, detection JSON): regular files only, one line at a time under a length and a
/// line-count limit, so a directory, a FIFO, /dev/zero or a huge file gets a reason instead of a
/// blocked or unbounded read. No paper equation.
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

namespace dyncull::text {

/// Why `path` cannot be read as a text file, or "" when it is a regular file (symbolic links are
/// followed). The reason names the path (escaped, see quote_path) and what it is instead: a directory,
/// a FIFO, a device, a socket, missing. Only the file's status is read, so this never blocks.
inline std::string regular_file_problem(const std::string& path) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  const std::string shown = quote_path(path);
  using std::filesystem::file_type;
  switch (st.type()) {
    case file_type::regular: return {};
    case file_type::not_found: return shown + ": no such file";
    case file_type::directory: return shown + ": is a directory, not a regular file";
    case file_type::fifo: return shown + ": is a FIFO (named pipe), not a regular file";
    case file_type::character: return shown + ": is a character device, not a regular file";
    case file_type::block: return shown + ": is a block device, not a regular file";
    case file_type::socket: return shown + ": is a socket, not a regular file";
    default: break;
  }
  return shown + ": cannot be read" + (ec ? " (" + ec.message() + ")" : std::string(", not a regular file"));
}

/// Limits of a LineReader. Each reader picks a line count that bounds the memory of what it keeps.
struct LineReaderOptions {
  std::size_t max_line_chars = kMaxLineChars;  ///< longer lines come back as TooLong, cut to this
  std::size_t max_lines = 1000000;             ///< lines (blank and comments included) before TooManyLines
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

  /// Opens `path`; false with error() = "path: why" when it is not a regular file (regular_file_problem)
  /// or cannot be opened. Error texts name the path escaped by quote_path.
  bool open(const std::string& path, const LineReaderOptions& options = {}) {
    options_ = options;
    path_ = quote_path(path);
    error_.clear();
    line_number_ = 0;
    line_chars_ = 0;
    pos_ = len_ = 0;
    done_ = false;
    file_.close();
    file_.clear();
    error_ = regular_file_problem(path);
    if (!error_.empty()) {
      done_ = true;
      return false;
    }
    file_.open(path, std::ios::in | std::ios::binary);
    if (!file_) {
      error_ = path_ + ": cannot open for reading";
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
    file_.read(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    len_ = static_cast<std::size_t>(file_.gcount());
    pos_ = 0;
    if (len_ > 0) return true;
    if (file_.bad() || !file_.eof()) error_ = path_ + ": read error";
    file_.close();
    return false;
  }

  LineReaderOptions options_;
  std::ifstream file_;
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
/// for what is not a regular file (regular_file_problem), cannot be read, or is larger (its size is
/// named). Never reads more than max_bytes + 1 bytes.
inline bool read_small_file(const std::string& path, std::size_t max_bytes, std::string* text, std::string* error) {
  text->clear();
  *error = regular_file_problem(path);
  if (!error->empty()) return false;
  std::ifstream file(path, std::ios::in | std::ios::binary);
  if (!file) {
    *error = quote_path(path) + ": cannot open for reading";
    return false;
  }
  char chunk[1 << 14];
  while (text->size() <= max_bytes) {
    file.read(chunk, sizeof chunk);
    const std::size_t got = static_cast<std::size_t>(file.gcount());
    if (got == 0) break;
    text->append(chunk, std::min(got, max_bytes + 1 - text->size()));
  }
  if (file.bad()) {
    *error = quote_path(path) + ": read error";
    text->clear();
    return false;
  }
  if (text->size() > max_bytes) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    *error = quote_path(path) + ": " + (ec ? std::string("more than ") : std::string()) +
             std::to_string(ec ? static_cast<std::uintmax_t>(max_bytes) : size) + " bytes, over the limit of " +
             std::to_string(max_bytes);
    text->clear();
    return false;
  }
  return true;
}

}  // namespace dyncull::text
