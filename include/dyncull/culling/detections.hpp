/// @file detections.hpp
/// Detector output -> pixel boxes: YOLO normalised (cx, cy, w, h) to corners X1 = (x - w/2) W,
/// X2 = (x + w/2) W, Y1 = (y - h/2) H, Y2 = (y + h/2) H (RTD-SLAM, Gao et al. 2024,
/// eq. 1-2; Zhang et al. 2023 eq. 1), undoing a letterbox.
///
/// API:
///   Box<T> yolo_to_pixel_box(const YoloBox<T>&, int width, int height, const Letterbox<T>& = {});
///   DetectionsResult<T> convert_yolo_detections(const std::vector<YoloBox<T>>&, int w, int h, const DetectionOptions<T>&,
///                                               const Letterbox<T>& = {});
///   DetectionsResult<T> filter_detections(const std::vector<Detection<T>>& pixel_boxes, int w, int h, const DetectionOptions<T>&);
///   YoloParseResult<T> parse_yolo_lines(std::string_view text, const std::string& source = "");  // "class cx cy w h [conf]" per line
///   add_yolo_line(line, line_chars, line_no, source, &result); finish_yolo_lines(&result);  // the same, streamed
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/text.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

namespace dyncull {

/// One raw YOLO output: normalised centre and size in [0, 1] of the network input.
template <class T>
struct YoloBox {
  int class_id = -1;
  T cx = T(0), cy = T(0), w = T(0), h = T(0);
  T confidence = T(1);
};

/// How the image was fitted into the network input. With `input_width <= 0` the normalised
/// coordinates refer to the image itself (plain resize, or labels files). Otherwise they refer to
/// an input_width x input_height tensor in which the image was scaled by `scale` and offset by
/// (pad_x, pad_y) pixels (YOLOv5 letterbox: scale = min(in_w / W, in_h / H), pad = half the rest).
template <class T>
struct Letterbox {
  int input_width = 0;
  int input_height = 0;
  T scale = T(1);
  T pad_x = T(0);
  T pad_y = T(0);

  /// The centred letterbox YOLOv5/v8 use for an image of width x height.
  static Letterbox centred(int image_width, int image_height, int in_w, int in_h) {
    Letterbox lb;
    lb.input_width = in_w;
    lb.input_height = in_h;
    if (image_width <= 0 || image_height <= 0) return lb;
    const T sx = T(in_w) / T(image_width), sy = T(in_h) / T(image_height);
    lb.scale = sx < sy ? sx : sy;
    lb.pad_x = (T(in_w) - lb.scale * T(image_width)) / T(2);
    lb.pad_y = (T(in_h) - lb.scale * T(image_height)) / T(2);
    return lb;
  }

  /// Ok, or InvalidInput naming the first bad field: a letterbox in use (input_width or input_height set)
  /// needs both sizes positive, a finite scale > 0 and finite pads.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const char* why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (input_width != 0 || input_height != 0) {
      if (input_width <= 0) return bad("letterbox.input_width must be positive when a letterbox is set");
      if (input_height <= 0) return bad("letterbox.input_height must be positive when a letterbox is set");
      if (!(scale > T(0)) || !std::isfinite(scale)) return bad("letterbox.scale must be positive and finite");
      if (!std::isfinite(pad_x)) return bad("letterbox.pad_x must be finite");
      if (!std::isfinite(pad_y)) return bad("letterbox.pad_y must be finite");
    }
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Why a detection was dropped.
enum class BoxRejection : std::uint8_t { None = 0, NonFinite, NonPositiveSize, OutsideImage, LowConfidence, BadClass };

constexpr const char* to_string(BoxRejection r) noexcept {
  switch (r) {
    case BoxRejection::None: return "kept";
    case BoxRejection::NonFinite: return "non-finite coordinates";
    case BoxRejection::NonPositiveSize: return "width or height <= 0";
    case BoxRejection::OutsideImage: return "entirely outside the image";
    case BoxRejection::LowConfidence: return "confidence below the class threshold";
    case BoxRejection::BadClass: return "negative class id";
  }
  return "unknown";
}

template <class T>
struct DetectionOptions {
  /// Grow every kept box by this many pixels on each side before clipping (Crowd-SLAM / CDS-SLAM
  /// use 5 px: detector boxes are tight and limbs stick out). Negative shrinks; a box the shrinking
  /// empties is dropped (NonPositiveSize), one it moves off the image too (OutsideImage).
  T box_padding_px = T(5);
  /// Minimum confidence for classes without their own entry.
  T min_confidence = T(0.4);
  /// Person (COCO id 0) threshold: lower, because a missed person costs more than a false one
  /// (SG-SLAM: 0.1 for person vs 0.985 for other classes).
  T min_confidence_person = T(0.25);
  int person_class_id = 0;

  T threshold_for(int class_id) const {
    return class_id == person_class_id ? min_confidence_person : min_confidence;
  }

  /// Ok, or InvalidInput naming the first bad field: box_padding_px finite; min_confidence and
  /// min_confidence_person in [0, 1].
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const std::string& why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    auto unit = [](T v) { return v >= T(0) && v <= T(1); };  // false for NaN
    if (!std::isfinite(box_padding_px)) return bad("box_padding_px must be finite");
    if (!unit(min_confidence)) return bad("min_confidence must be in [0, 1]");
    if (!unit(min_confidence_person)) return bad("min_confidence_person must be in [0, 1]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

template <class T>
struct DetectionsResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::vector<Detection<T>> detections;     ///< kept boxes, padded and clipped to [0, W-1] x [0, H-1]
  std::vector<int> source_index;            ///< input index of each kept box
  std::vector<BoxRejection> rejections;     ///< one per input (None = kept)
  std::size_t num_input = 0, num_kept = 0, num_invalid = 0, num_outside = 0, num_low_confidence = 0;
};

/// Unclipped pixel corners of a YOLO box (no padding, no validity checks).
template <class T>
Box<T> yolo_to_pixel_box(const YoloBox<T>& b, int width, int height, const Letterbox<T>& lb = {}) {
  const bool boxed = lb.input_width > 0 && lb.input_height > 0 && lb.scale > T(0);
  const T sx = boxed ? T(lb.input_width) : T(width);
  const T sy = boxed ? T(lb.input_height) : T(height);
  Box<T> out{(b.cx - b.w / T(2)) * sx, (b.cy - b.h / T(2)) * sy, (b.cx + b.w / T(2)) * sx, (b.cy + b.h / T(2)) * sy};
  if (boxed) {
    out = Box<T>{(out.x0 - lb.pad_x) / lb.scale, (out.y0 - lb.pad_y) / lb.scale, (out.x1 - lb.pad_x) / lb.scale,
                 (out.y1 - lb.pad_y) / lb.scale};
  }
  return out;
}

namespace detail {
template <class T>
BoxRejection check_and_finish_box(Box<T>* box, T confidence, int class_id, int width, int height,
                                  const DetectionOptions<T>& o) {
  if (class_id < 0) return BoxRejection::BadClass;
  if (!box->finite() || !std::isfinite(confidence)) return BoxRejection::NonFinite;
  if (!(box->x1 > box->x0) || !(box->y1 > box->y0)) return BoxRejection::NonPositiveSize;
  if (box->x1 < T(0) || box->y1 < T(0) || box->x0 > T(width - 1) || box->y0 > T(height - 1))
    return BoxRejection::OutsideImage;
  if (confidence < o.threshold_for(class_id)) return BoxRejection::LowConfidence;
  // Negative padding shrinks: a box it empties, or moves off the image, is not a box any more.
  const Box<T> padded = box->padded(o.box_padding_px);
  if (!(padded.x1 > padded.x0) || !(padded.y1 > padded.y0)) return BoxRejection::NonPositiveSize;
  const Box<T> clipped = padded.clipped(width, height);
  if (!clipped.valid()) return BoxRejection::OutsideImage;
  *box = clipped;
  return BoxRejection::None;
}

template <class T>
void tally(DetectionsResult<T>* r, BoxRejection why) {
  r->rejections.push_back(why);
  if (why == BoxRejection::None) ++r->num_kept;
  else if (why == BoxRejection::OutsideImage) ++r->num_outside;
  else if (why == BoxRejection::LowConfidence) ++r->num_low_confidence;
  else ++r->num_invalid;
}

template <class T>
void finish(DetectionsResult<T>* r, int width, int height) {
  if (width <= 0 || height <= 0) {
    r->status = Status::InvalidInput;
    r->reason.assign("image size must be positive");
    return;
  }
  if (r->num_kept < r->num_input) {
    std::string& why = r->reason;  // built in place: a reused result keeps the string's capacity
    why.assign(std::to_string(r->num_input - r->num_kept));
    why += " of ";
    why += std::to_string(r->num_input);
    why += " boxes rejected (";
    why += std::to_string(r->num_invalid);
    why += " invalid, ";
    why += std::to_string(r->num_outside);
    why += " outside, ";
    why += std::to_string(r->num_low_confidence);
    why += " low confidence)";
  }
}
}  // namespace detail

/// Converts, filters, pads and clips YOLO boxes, undoing the letterbox the detector fitted the image
/// into (none: the boxes are normalised to the image). Rejected boxes do not make the call fail: status
/// stays Ok and `reason` / `rejections` say what was dropped. InvalidInput (no boxes kept, no
/// rejections listed) for a bad image size, options that fail DetectionOptions::validate or a letterbox
/// that fails Letterbox::validate.
template <class T>
DetectionsResult<T> convert_yolo_detections(const std::vector<YoloBox<T>>& boxes, int width, int height,
                                            const DetectionOptions<T>& options = {},
                                            const Letterbox<T>& letterbox = {}) {
  DetectionsResult<T> r;
  r.num_input = boxes.size();
  if (width <= 0 || height <= 0) {
    detail::finish(&r, width, height);
    return r;
  }
  if (options.validate(&r.reason) != Status::Ok || letterbox.validate(&r.reason) != Status::Ok) {
    r.status = Status::InvalidInput;
    return r;
  }
  r.rejections.reserve(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const YoloBox<T>& b = boxes[i];
    Box<T> px = yolo_to_pixel_box(b, width, height, letterbox);
    // w, h are tested on the normalised input too: a NaN/negative size must not survive the letterbox.
    BoxRejection why = !(std::isfinite(b.cx) && std::isfinite(b.cy) && std::isfinite(b.w) && std::isfinite(b.h))
                           ? BoxRejection::NonFinite
                           : (!(b.w > T(0)) || !(b.h > T(0)) ? BoxRejection::NonPositiveSize : BoxRejection::None);
    if (why == BoxRejection::None) why = detail::check_and_finish_box(&px, b.confidence, b.class_id, width, height, options);
    detail::tally(&r, why);
    if (why == BoxRejection::None) {
      r.detections.push_back(Detection<T>{px, b.class_id, b.confidence});
      r.source_index.push_back(static_cast<int>(i));
    }
  }
  detail::finish(&r, width, height);
  return r;
}

/// Same checks, padding and clipping for boxes already in pixels (e.g. after the detector's own
/// post-processing), and the same InvalidInput cases; writes into `*out`, reusing its buffers.
template <class T>
void filter_detections(const std::vector<Detection<T>>& boxes, int width, int height,
                       const DetectionOptions<T>& options, DetectionsResult<T>* out) {
  DetectionsResult<T>& r = *out;
  r.status = Status::Ok;
  r.reason.clear();
  r.detections.clear();
  r.source_index.clear();
  r.rejections.clear();
  r.num_kept = r.num_invalid = r.num_outside = r.num_low_confidence = 0;
  r.num_input = boxes.size();
  if (width <= 0 || height <= 0) {
    detail::finish(&r, width, height);
    return;
  }
  if (options.validate(&r.reason) != Status::Ok) {
    r.status = Status::InvalidInput;
    return;
  }
  r.rejections.reserve(boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    Box<T> px = boxes[i].box;
    const BoxRejection why =
        detail::check_and_finish_box(&px, boxes[i].confidence, boxes[i].class_id, width, height, options);
    detail::tally(&r, why);
    if (why == BoxRejection::None) {
      r.detections.push_back(Detection<T>{px, boxes[i].class_id, boxes[i].confidence});
      r.source_index.push_back(static_cast<int>(i));
    }
  }
  detail::finish(&r, width, height);
}

/// The same filter returning a fresh result (allocates; the out-parameter form reuses buffers).
template <class T>
DetectionsResult<T> filter_detections(const std::vector<Detection<T>>& boxes, int width, int height,
                                      const DetectionOptions<T>& options = {}) {
  DetectionsResult<T> r;
  filter_detections(boxes, width, height, options, &r);
  return r;
}

/// One unparseable line of a YOLO text file (1-based line number; message without "source:line: ").
struct YoloParseError {
  int line = 0;
  std::string message;
};

/// Bad lines listed in YoloParseResult::errors; the rest are only counted.
constexpr std::size_t kYoloMaxListedErrors = 16;

template <class T>
struct YoloParseResult {
  Status status = Status::Ok;
  std::string reason;  ///< "source:line: why (N bad lines)" of the first bad line ("line N: ..." without a source)
  bool ok() const { return status == Status::Ok; }
  std::vector<YoloBox<T>> boxes;  ///< every line that parsed, in file order
  std::vector<int> line_of_box;   ///< 1-based line number of each box
  std::vector<YoloParseError> errors;  ///< the first kYoloMaxListedErrors bad lines
  std::size_t num_bad_lines = 0;       ///< every bad line
};

namespace detail {
inline bool is_yolo_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Why one YOLO line does not parse ("" when it does; then *box holds it). `line_chars` is the line's
/// full length when `line` holds only its first text::kMaxLineChars bytes.
template <class T>
std::string parse_yolo_line(std::string_view line, std::size_t line_chars, YoloBox<T>* box) {
  if (line_chars > text::kMaxLineChars)
    return "line is " + std::to_string(line_chars) + " bytes long (limit " + std::to_string(text::kMaxLineChars) + ")";
  static const char* const kNames[6] = {"class", "cx", "cy", "w", "h", "conf"};
  std::string_view tokens[6];
  std::size_t n = 0;
  for (std::size_t k = 0; k < line.size();) {
    while (k < line.size() && is_yolo_space(line[k])) ++k;
    if (k == line.size()) break;
    const std::size_t start = k;
    while (k < line.size() && !is_yolo_space(line[k])) ++k;
    if (n < 6) tokens[n] = line.substr(start, k - start);
    ++n;
  }
  if (n < 5 || n > 6) return "expected 5 or 6 fields (class cx cy w h [conf]), got " + std::to_string(n);
  double v[6] = {0, 0, 0, 0, 0, 1};
  for (std::size_t c = 0; c < n; ++c) {
    const text::NumberStatus st = text::parse_python_float(tokens[c], &v[c]);
    if (st == text::NumberStatus::TooLong)
      return std::string(kNames[c]) + " " + text::quote_token(tokens[c]) + " is longer than " +
             std::to_string(text::kMaxNumberChars) + " characters";
    if (st != text::NumberStatus::Ok) return std::string(kNames[c]) + " " + text::quote_token(tokens[c]) + " is not a number";
    // A finite double beyond T's range would become inf through an undefined cast.
    if (c > 0 && !text::fits_scalar<T>(v[c]))
      return std::string(kNames[c]) + " " + text::quote_token(tokens[c]) + " is out of range for " + text::scalar_name<T>();
  }
  long long class_id = 0;
  if (!text::integer_in_range(v[0], 0, 1000000, &class_id))
    return "class id " + text::quote_token(tokens[0]) + " must be an integer in [0, 1000000]";
  box->class_id = static_cast<int>(class_id);
  box->cx = T(v[1]);
  box->cy = T(v[2]);
  box->w = T(v[3]);
  box->h = T(v[4]);
  box->confidence = T(v[5]);
  return {};
}
}  // namespace detail

/// One line of YOLO text into `r`: the streaming form of parse_yolo_lines, for a reader that hands
/// over a file line by line (text::LineReader). `line_chars` is the line's full length when `line`
/// holds only its first text::kMaxLineChars bytes; `line_no` is 1-based; `source` names the input in
/// the reason. Call finish_yolo_lines(&r) after the last line.
template <class T>
void add_yolo_line(std::string_view line, std::size_t line_chars, int line_no, const std::string& source,
                   YoloParseResult<T>* r) {
  std::size_t first = 0;
  while (first < line.size() && detail::is_yolo_space(line[first])) ++first;
  if (first == line.size() && line_chars == line.size()) return;  // blank
  if (first < line.size() && line[first] == '#') return;          // comment, whatever its length
  YoloBox<T> b;
  std::string why = detail::parse_yolo_line(line, line_chars, &b);
  if (why.empty()) {
    r->boxes.push_back(b);
    r->line_of_box.push_back(line_no);
    return;
  }
  if (r->num_bad_lines == 0) {
    r->reason = (source.empty() ? "line " : text::quote_path(source) + ":") + std::to_string(line_no) + ": " + why;
  }
  ++r->num_bad_lines;
  if (r->errors.size() < kYoloMaxListedErrors) r->errors.push_back(YoloParseError{line_no, std::move(why)});
}

/// Sets the status and the bad-line count of the reason after the last add_yolo_line().
template <class T>
void finish_yolo_lines(YoloParseResult<T>* r) {
  if (r->num_bad_lines > 0) {
    r->status = Status::ParseError;
    r->reason += " (" + std::to_string(r->num_bad_lines) + (r->num_bad_lines == 1 ? " bad line)" : " bad lines)");
  }
}

/// Parses YOLO text ("class cx cy w h [conf]" per line, space or tab separated; blank lines and '#'
/// comments skipped). Numbers follow Python's float() whatever the C locale ("0,5" is an error, 1e400
/// is inf). Bad lines are skipped, counted and the first kYoloMaxListedErrors listed; status is
/// ParseError when any line failed (the good boxes are still returned), `reason` names the first as
/// "source:line: why" (`source` escaped by text::quote_path). Bounded: a line over
/// text::kMaxLineChars or a number over text::kMaxNumberChars characters is a bad line, and reasons
/// quote at most 32 escaped characters of a token. A value outside T's finite range (1e39 for float)
/// is a bad line; validity of the numbers (w > 0, finite) is left to convert_yolo_detections, which
/// reports it per box.
template <class T>
YoloParseResult<T> parse_yolo_lines(std::string_view text, const std::string& source = "") {
  YoloParseResult<T> r;
  std::size_t pos = 0;
  int line_no = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    add_yolo_line(line.substr(0, text::kMaxLineChars), line.size(), line_no, source, &r);
  }
  finish_yolo_lines(&r);
  return r;
}

}  // namespace dyncull
