/// @file yolo_json.hpp
/// Reader of per-frame detector output as JSON (`NNNNNN.json`: frame_id, timestamp, detections[] with
/// class_id, confidence, bbox [x1, y1, x2, y2] in pixels), the format of YOLOv8 (Jocher et al. 2023)
/// runs on TUM RGB-D sequences (Sturm et al. 2012). No paper equation: a strict, bounded JSON subset.
///
/// API:
///   YoloJsonFrame<float> f = parse_yolo_json<float>(text, "000012.json");  // or read_yolo_json<float>(path)
///   f.frame_id, f.timestamp, f.detections (Detection<T>: box, class_id, confidence)
///   YoloJsonSequence<float> s = read_yolo_json_sequence<float>(dir);  // dir/000000.json, 000001.json, ...
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/text.hpp"
#include "dyncull/core/text_file.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace dyncull::eval {

/// Bounds of the reader: input beyond them is a ParseError (or IoError for the file size), never a
/// large allocation or a deep recursion.
struct YoloJsonOptions {
  std::size_t max_bytes = std::size_t(1) << 22;  ///< a file (4 MiB; the real files are ~2 kB)
  std::size_t max_detections = 10000;           ///< entries of detections[]
  int max_depth = 32;                           ///< nesting of arrays and objects
  std::size_t max_string_chars = 4096;          ///< one string's length in the file
  std::size_t max_frames = 1000000;             ///< files read by read_yolo_json_sequence
};

/// One frame's detections. On error status is ParseError (IoError for an unreadable file), reason
/// is "source: byte B (line L, column C): why", and the other fields are left empty.
template <class T>
struct YoloJsonFrame {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  long long frame_id = -1;
  double timestamp = 0;                ///< seconds (double whatever T is: 1.3e9 s needs 53 bits)
  std::vector<Detection<T>> detections;  ///< file order; boxes as written (x1, y1, x2, y2 in pixels)
};

/// Frames 0..N-1 of a directory, read until the first missing NNNNNN.json.
template <class T>
struct YoloJsonSequence {
  Status status = Status::Ok;
  std::string reason;  ///< the first bad file's reason; frames before it are kept
  bool ok() const { return status == Status::Ok; }
  std::vector<YoloJsonFrame<T>> frames;
};

namespace detail {

/// Recursive-descent JSON (RFC 8259) validator that keeps only the fields the frame needs. Unknown
/// keys are parsed and skipped, so a malformed value anywhere is an error.
template <class T>
class YoloJsonParser {
 public:
  /// frame_id: a frame number, exact in the double a JSON number is read as (2^53 is 9.0e15).
  static constexpr long long kMaxFrameId = 1000000000000000LL;
  static constexpr const char* kFrameIdRange = "a frame number up to 10^15, exact in the double a JSON number is read as";
  /// class_id: far above any detector's class count, small enough for an int.
  static constexpr long long kMaxClassId = 1000000;
  static constexpr const char* kClassIdRange = "a detector class index";

  YoloJsonParser(std::string_view text, const YoloJsonOptions& options) : s_(text), o_(options) {}

  /// Fills `out` (frame_id, timestamp, detections); false with error() set on the first problem.
  bool parse(YoloJsonFrame<T>* out) {
    skip_ws();
    if (!expect('{', "the file must hold one JSON object")) return false;
    bool has_id = false, has_stamp = false, has_dets = false;
    if (!object_members([&](const std::string& key) {
          if (key == "frame_id") return unique(&has_id, key) && integer(&out->frame_id, 0, kMaxFrameId, key, kFrameIdRange);
          if (key == "timestamp") return unique(&has_stamp, key) && number(&out->timestamp, key);
          if (key == "detections") return unique(&has_dets, key) && detections(&out->detections);
          return skip_value(1);
        }))
      return false;
    skip_ws();
    if (pos_ != s_.size()) return fail("unexpected content after the JSON object");
    if (!has_id) return fail_at(s_.size(), "missing \"frame_id\"");
    if (!has_stamp) return fail_at(s_.size(), "missing \"timestamp\"");
    if (!has_dets) return fail_at(s_.size(), "missing \"detections\"");
    return true;
  }

  const std::string& error() const { return error_; }
  std::size_t error_pos() const { return error_pos_; }

 private:
  std::string_view s_;
  const YoloJsonOptions& o_;
  std::size_t pos_ = 0;
  std::string error_;
  std::size_t error_pos_ = 0;

  bool fail(const std::string& why) { return fail_at(pos_, why); }
  bool fail_at(std::size_t at, const std::string& why) {
    if (error_.empty()) {
      error_ = why;
      error_pos_ = at;
    }
    return false;
  }
  bool at_end() const { return pos_ >= s_.size(); }
  char peek() const { return at_end() ? '\0' : s_[pos_]; }
  void skip_ws() {
    while (!at_end() && (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r')) ++pos_;
  }
  static std::string shown(char c) {
    if (c >= 0x20 && c < 0x7f) return std::string("'") + c + "'";
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02x", static_cast<unsigned>(static_cast<unsigned char>(c)));
    return buf;
  }
  bool expect(char c, const char* why) {
    if (peek() != c)
      return fail(std::string(why) + " (expected '" + c + "', found " + (at_end() ? "end of input" : shown(peek())) + ")");
    ++pos_;
    return true;
  }
  bool unique(bool* seen, const std::string& key) {
    if (*seen) return fail("duplicate key \"" + key + "\"");
    *seen = true;
    return true;
  }

  /// Members of an object whose '{' was consumed: "key": value pairs, the value read by `member`.
  template <class Member>
  bool object_members(Member&& member) {
    skip_ws();
    if (peek() == '}') {
      ++pos_;
      return true;
    }
    while (true) {
      skip_ws();
      std::string key;
      if (peek() != '"') return fail("expected a string key");
      if (!string(&key)) return false;
      skip_ws();
      if (!expect(':', "expected ':' after a key")) return false;
      skip_ws();
      if (!member(key)) return false;
      skip_ws();
      if (peek() == ',') {
        ++pos_;
        continue;
      }
      return expect('}', "expected ',' or '}' in an object");
    }
  }

  /// A string at pos_ (on '"'); `out` gets its text with escapes decoded (non-ASCII \u as '?').
  bool string(std::string* out) {
    const std::size_t start = pos_;
    ++pos_;
    std::size_t chars = 0;
    while (true) {
      if (at_end()) return fail_at(start, "unterminated string");
      const char c = s_[pos_];
      if (++chars > o_.max_string_chars)
        return fail_at(start, "string longer than " + std::to_string(o_.max_string_chars) + " characters");
      if (c == '"') {
        ++pos_;
        return true;
      }
      if (static_cast<unsigned char>(c) < 0x20) return fail("control character " + shown(c) + " in a string");
      if (c != '\\') {
        if (out) out->push_back(c);
        ++pos_;
        continue;
      }
      ++pos_;
      if (at_end()) return fail_at(start, "unterminated string");
      const char e = s_[pos_++];
      char decoded = '\0';
      switch (e) {
        case '"': decoded = '"'; break;
        case '\\': decoded = '\\'; break;
        case '/': decoded = '/'; break;
        case 'b': decoded = '\b'; break;
        case 'f': decoded = '\f'; break;
        case 'n': decoded = '\n'; break;
        case 'r': decoded = '\r'; break;
        case 't': decoded = '\t'; break;
        case 'u': {
          unsigned v = 0;
          for (int k = 0; k < 4; ++k, ++pos_) {
            const char h = peek();
            const int d = h >= '0' && h <= '9' ? h - '0'
                          : (h >= 'a' && h <= 'f' ? h - 'a' + 10 : (h >= 'A' && h <= 'F' ? h - 'A' + 10 : -1));
            if (d < 0) return fail("bad \\u escape in a string");
            v = v * 16 + static_cast<unsigned>(d);
          }
          decoded = v < 0x80 ? static_cast<char>(v) : '?';
          break;
        }
        default: pos_ -= 1; return fail("bad escape \\" + shown(e) + " in a string");  // e may be any byte
      }
      if (out) out->push_back(decoded);
    }
  }

  /// A JSON number at pos_ (strict grammar: -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?), finite in
  /// double. `integral` tells whether it had no fraction and no exponent.
  bool number_token(double* value, bool* integral, const std::string& what) {
    const std::size_t start = pos_;
    auto digit = [&]() { return !at_end() && s_[pos_] >= '0' && s_[pos_] <= '9'; };
    if (peek() == '-') ++pos_;
    if (!digit()) return fail_at(start, what + " must be a number");
    if (s_[pos_] == '0') {
      ++pos_;
      if (digit()) return fail_at(start, what + " has a leading zero");
    } else {
      while (digit()) ++pos_;
    }
    *integral = true;
    if (peek() == '.') {
      ++pos_;
      *integral = false;
      if (!digit()) return fail(what + " needs digits after '.'");
      while (digit()) ++pos_;
    }
    if (peek() == 'e' || peek() == 'E') {
      ++pos_;
      *integral = false;
      if (peek() == '+' || peek() == '-') ++pos_;
      if (!digit()) return fail(what + " needs digits in its exponent");
      while (digit()) ++pos_;
    }
    const std::string_view token = s_.substr(start, pos_ - start);
    if (token.size() > text::kMaxNumberChars)
      return fail_at(start, what + " is longer than " + std::to_string(text::kMaxNumberChars) + " characters");
    if (text::parse_python_float(token, value) != text::NumberStatus::Ok) return fail_at(start, what + " is not a number");
    if (!std::isfinite(*value)) return fail_at(start, what + " " + text::quote_token(token) + " is out of range");
    return true;
  }

  bool number(double* out, const std::string& what) {
    if (peek() == 'N' || peek() == 'I' || (peek() == '-' && pos_ + 1 < s_.size() && s_[pos_ + 1] == 'I'))
      return fail(what + " is NaN or Infinity, which JSON does not allow");
    bool integral = false;
    return number_token(out, &integral, what);
  }

  /// A number whose value is an integer in [lo, hi], in any notation (1e3 and 1000.0 are 1000, as
  /// Python's json reads them); `why_range` says where the bounds come from.
  bool integer(long long* out, long long lo, long long hi, const std::string& what, const char* why_range) {
    const std::size_t start = pos_;
    double v = 0;
    bool integral = false;
    if (!number_token(&v, &integral, what)) return false;
    if (!text::integer_in_range(v, lo, hi, out))
      return fail_at(start, what + " must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (" +
                                why_range + "), got " + text::quote_token(s_.substr(start, pos_ - start)));
    return true;
  }

  bool scalar(T* out, const std::string& what) {
    const std::size_t start = pos_;
    double v = 0;
    if (!number(&v, what)) return false;
    if (!text::fits_scalar<T>(v)) return fail_at(start, what + " is out of range for " + text::scalar_name<T>());
    *out = static_cast<T>(v);
    return true;
  }

  bool detections(std::vector<Detection<T>>* out) {
    if (!expect('[', "\"detections\" must be an array")) return false;
    skip_ws();
    if (peek() == ']') {
      ++pos_;
      return true;
    }
    while (true) {
      skip_ws();
      if (out->size() >= o_.max_detections)
        return fail("more than " + std::to_string(o_.max_detections) + " detections");
      const std::string index = "detections[" + std::to_string(out->size()) + "]";
      if (!expect('{', (index + " must be an object").c_str())) return false;
      Detection<T> d;
      bool has_class = false, has_conf = false, has_box = false;
      if (!object_members([&](const std::string& key) {
            if (key == "class_id") {
              long long c = -1;
              if (!unique(&has_class, index + "." + key) || !integer(&c, 0, kMaxClassId, index + ".class_id", kClassIdRange)) return false;
              d.class_id = static_cast<int>(c);
              return true;
            }
            if (key == "confidence") return unique(&has_conf, index + "." + key) && scalar(&d.confidence, index + ".confidence");
            if (key == "bbox") return unique(&has_box, index + "." + key) && bbox(&d.box, index + ".bbox");
            return skip_value(3);
          }))
        return false;
      if (!has_class) return fail(index + " has no \"class_id\"");
      if (!has_conf) return fail(index + " has no \"confidence\"");
      if (!has_box) return fail(index + " has no \"bbox\"");
      out->push_back(d);
      skip_ws();
      if (peek() == ',') {
        ++pos_;
        continue;
      }
      return expect(']', "expected ',' or ']' in \"detections\"");
    }
  }

  bool bbox(Box<T>* box, const std::string& what) {
    if (!expect('[', (what + " must be an array of 4 numbers").c_str())) return false;
    T v[4] = {T(0), T(0), T(0), T(0)};
    for (int k = 0; k < 4; ++k) {
      skip_ws();
      if (!scalar(&v[k], what + "[" + std::to_string(k) + "]")) return false;
      skip_ws();
      if (!expect(k < 3 ? ',' : ']', (what + " must be an array of 4 numbers").c_str())) return false;
    }
    *box = Box<T>{v[0], v[1], v[2], v[3]};
    return true;
  }

  bool literal(const char* word) {
    const std::string_view w(word);
    if (s_.substr(pos_, w.size()) != w) return fail("unexpected " + shown(peek()));
    pos_ += w.size();
    return true;
  }

  /// Any JSON value, checked and dropped.
  bool skip_value(int depth) {
    if (depth > o_.max_depth) return fail("nesting deeper than " + std::to_string(o_.max_depth));
    skip_ws();
    const char c = peek();
    if (at_end()) return fail("unexpected end of input");
    if (c == '"') return string(nullptr);
    if (c == '{') {
      ++pos_;
      return object_members([&](const std::string&) { return skip_value(depth + 1); });
    }
    if (c == '[') {
      ++pos_;
      skip_ws();
      if (peek() == ']') {
        ++pos_;
        return true;
      }
      while (true) {
        if (!skip_value(depth + 1)) return false;
        skip_ws();
        if (peek() == ',') {
          ++pos_;
          continue;
        }
        return expect(']', "expected ',' or ']' in an array");
      }
    }
    if (c == 't') return literal("true");
    if (c == 'f') return literal("false");
    if (c == 'n') return literal("null");
    double v = 0;
    return number(&v, "value");
  }
};

/// "byte B (line L, column C)" of a position in `text` (1-based line and column).
inline std::string json_position(std::string_view text, std::size_t pos) {
  std::size_t line = 1, column = 1;
  for (std::size_t k = 0; k < pos && k < text.size(); ++k) {
    if (text[k] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return "byte " + std::to_string(pos) + " (line " + std::to_string(line) + ", column " + std::to_string(column) + ")";
}

}  // namespace detail

/// Parses one frame's JSON. Locale-independent; `source` names the input in reasons.
template <class T>
YoloJsonFrame<T> parse_yolo_json(std::string_view text, const std::string& source = "<memory>",
                                 const YoloJsonOptions& options = {}) {
  YoloJsonFrame<T> out;
  if (text.size() > options.max_bytes) {
    out.status = Status::ParseError;
    out.reason = text::quote_path(source) + ": " + std::to_string(text.size()) + " bytes, over the limit of " +
                 std::to_string(options.max_bytes);
    return out;
  }
  detail::YoloJsonParser<T> parser(text, options);
  if (!parser.parse(&out)) {
    YoloJsonFrame<T> bad;
    bad.status = Status::ParseError;
    bad.reason = text::quote_path(source) + ": " + detail::json_position(text, parser.error_pos()) + ": " + parser.error();
    return bad;
  }
  return out;
}

/// Reads and parses one file: IoError when the path is not a regular file (a directory, a FIFO, a
/// device: refused before reading, named), cannot be read, or is over options.max_bytes (never reads
/// more than that).
template <class T>
YoloJsonFrame<T> read_yolo_json(const std::string& path, const YoloJsonOptions& options = {}) {
  YoloJsonFrame<T> out;
  std::string text;
  if (!text::read_small_file(path, options.max_bytes, &text, &out.reason)) {
    out.status = Status::IoError;
    return out;
  }
  return parse_yolo_json<T>(text, path, options);
}

/// Reads dir/000000.json, dir/000001.json, ... until the first that does not exist. Each file's
/// frame_id must equal its number. Stops at the first bad file (status and reason from it).
template <class T>
YoloJsonSequence<T> read_yolo_json_sequence(const std::string& dir, const YoloJsonOptions& options = {}) {
  YoloJsonSequence<T> seq;
  for (std::size_t k = 0; k < options.max_frames; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "/%06zu.json", k);
    const std::string path = dir + name;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) break;  // opening it to find out would block on a FIFO
    YoloJsonFrame<T> f = read_yolo_json<T>(path, options);
    if (!f.ok()) {
      seq.status = f.status;
      seq.reason = f.reason;
      return seq;
    }
    if (f.frame_id != static_cast<long long>(k)) {
      seq.status = Status::ParseError;
      seq.reason = text::quote_path(path) + ": frame_id " + std::to_string(f.frame_id) + " differs from the file's number " + std::to_string(k);
      return seq;
    }
    seq.frames.push_back(std::move(f));
  }
  if (seq.frames.empty()) {
    seq.status = Status::IoError;
    seq.reason = text::quote_path(dir) + ": no 000000.json";
  }
  return seq;
}

}  // namespace dyncull::eval
