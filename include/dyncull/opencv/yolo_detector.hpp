/// @file yolo_detector.hpp
/// A real detector source on OpenCV DNN: a YOLO network (Darknet cfg/weights with YOLOv3-style [yolo]
/// heads, Redmon & Farhadi 2018; or an ONNX export of YOLOv5 / YOLOv8, Jocher et al., Ultralytics
/// software) run on a BGR frame, returning the culler's Detection<float> boxes (COCO-80 ids) in pixels.
/// Confidence = objectness x class score (YOLOv8 has no objectness: the class score), per-class NMS
/// (cv::dnn::NMSBoxes), boxes clipped to [0, W-1] x [0, H-1], empty ones dropped.
///
/// Needs OpenCV's dnn module: link dyncull::opencv_dnn (the rest of the OpenCV adapter does not).
///
/// API:
///   cv_adapter::YoloDetectorOptions o;  o.model = "yolo.cfg";  o.weights = "yolo.weights";
///   cv_adapter::YoloDetector detector;
///   cv_adapter::YoloOpenResult opened = detector.open(o);        // check opened.ok(), opened.reason
///   const cv_adapter::YoloDetectorResult& r = detector.detect(bgr);  // r.detections, r.status, r.reason
///   cv_adapter::decode_yolo_outputs(raw_outputs, head, geometry, o, &scratch, &result);  // without a network
#pragma once

#include "dyncull/core/box.hpp"
#include "dyncull/core/pixel.hpp"
#include "dyncull/core/status.hpp"
#include "dyncull/core/text.hpp"
#include "dyncull/core/text_file.hpp"
#include "dyncull/opencv/darknet_layout.hpp"

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <string>
#include <vector>

namespace dyncull {
namespace cv_adapter {

/// Layout of the network's raw output.
enum class YoloHead {
  Auto,     ///< from the model file and the output shape
  Darknet,  ///< one 2-D [N, 5 + C] Mat per [yolo] layer as OpenCV's region layer writes it: normalised
            ///< cx, cy, w, h, objectness, then class scores already multiplied by the objectness
  YoloV5,   ///< [1, N, 5 + C]: cx, cy, w, h in input pixels, objectness, class scores
  YoloV8,   ///< [1, 4 + C, N]: cx, cy, w, h in input pixels, class scores (no objectness)
};

constexpr const char* to_string(YoloHead h) noexcept {
  switch (h) {
    case YoloHead::Auto: return "auto";
    case YoloHead::Darknet: return "darknet";
    case YoloHead::YoloV5: return "yolov5";
    case YoloHead::YoloV8: return "yolov8";
  }
  return "unknown";
}

/// How the frame is fitted into the network input.
enum class YoloResize {
  Plain,      ///< stretched to the input size, as cv::dnn::blobFromImage does
  Letterbox,  ///< scaled by min(in_w / W, in_h / H), centred, the rest filled (YOLOv5 / YOLOv8 export)
};

/// Size caps of the model files (the file-opening rule of core/text_file.hpp): a Darknet cfg is a few
/// kB of text; the largest YOLO weights and ONNX exports are a few hundred MB.
constexpr std::uint64_t kMaxYoloCfgBytes = std::uint64_t(1) << 20;
constexpr std::uint64_t kMaxYoloModelBytes = std::uint64_t(1) << 30;

struct YoloDetectorOptions {
  std::string model;    ///< Darknet .cfg or .onnx
  std::string weights;  ///< Darknet .weights (required with a .cfg; empty for ONNX)
  YoloHead head = YoloHead::Auto;
  int input_width = 416;   ///< network input, a multiple of 32 for YOLO
  int input_height = 416;
  YoloResize resize = YoloResize::Plain;
  double letterbox_fill = 114;  ///< grey level of the letterbox border (YOLOv5's)
  bool swap_rb = true;          ///< YOLO networks are trained on RGB; frames come in as BGR
  float min_confidence = 0.25f;  ///< on objectness x class score (>=)
  float nms_iou = 0.45f;         ///< per class
  int num_classes = 80;          ///< COCO-80; the output shape must agree
  /// Darknet heads only: multiply OpenCV's class scores, which already include the objectness, by the
  /// objectness once more (confidence = objectness^2 x class score, thresholded as such). Not YOLO's
  /// confidence; it is what applying the YOLOv5 formula to OpenCV's Darknet output gives, so set it to
  /// reproduce boxes made that way.
  bool reapply_objectness = false;

  /// Ok, or InvalidInput naming the first bad field.
  Status validate(std::string* reason = nullptr) const {
    auto bad = [&](const std::string& why) {
      if (reason) *reason = why;
      return Status::InvalidInput;
    };
    if (input_width <= 0 || input_height <= 0 || input_width > 4096 || input_height > 4096)
      return bad("input_width and input_height must be in [1, 4096], got " + std::to_string(input_width) + " x " +
                 std::to_string(input_height));
    if (!(min_confidence >= 0.f && min_confidence <= 1.f)) return bad("min_confidence must be in [0, 1]");
    if (!(nms_iou >= 0.f && nms_iou <= 1.f)) return bad("nms_iou must be in [0, 1]");
    if (num_classes < 1 || num_classes > 100000) return bad("num_classes must be in [1, 100000]");
    if (!(letterbox_fill >= 0 && letterbox_fill <= 255)) return bad("letterbox_fill must be in [0, 255]");
    if (reason) reason->clear();
    return Status::Ok;
  }
};

/// Where the frame sits in the network input: x_input = x_image * scale_x + offset_x (same for y).
struct YoloInputGeometry {
  int image_width = 0, image_height = 0;
  int input_width = 0, input_height = 0;
  double scale_x = 1, scale_y = 1;
  double offset_x = 0, offset_y = 0;

  /// Plain resize: the image stretched over the whole input.
  static YoloInputGeometry plain(int image_w, int image_h, int in_w, int in_h) {
    YoloInputGeometry g;
    g.image_width = image_w;
    g.image_height = image_h;
    g.input_width = in_w;
    g.input_height = in_h;
    if (image_w > 0 && image_h > 0) {
      g.scale_x = double(in_w) / image_w;
      g.scale_y = double(in_h) / image_h;
    }
    return g;
  }
  /// Letterbox: one scale, the scaled image rounded to whole pixels and centred (integer offsets).
  static YoloInputGeometry letterbox(int image_w, int image_h, int in_w, int in_h) {
    YoloInputGeometry g = plain(image_w, image_h, in_w, in_h);
    if (image_w <= 0 || image_h <= 0) return g;
    const double s = std::min(double(in_w) / image_w, double(in_h) / image_h);
    const int w = clamped_int(std::round(image_w * s), 1, std::max(1, in_w));
    const int h = clamped_int(std::round(image_h * s), 1, std::max(1, in_h));
    g.scale_x = double(w) / image_w;
    g.scale_y = double(h) / image_h;
    g.offset_x = (in_w - w) / 2;
    g.offset_y = (in_h - h) / 2;
    return g;
  }
  int scaled_width() const { return clamped_int(std::round(image_width * scale_x), 0, std::numeric_limits<int>::max()); }
  int scaled_height() const { return clamped_int(std::round(image_height * scale_y), 0, std::numeric_limits<int>::max()); }
};

/// One frame's detections. On error status says which kind (InvalidInput: the image or the options;
/// ParseError: the network failed at run time) and the detections are empty.
struct YoloDetectorResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  std::vector<Detection<float>> detections;  ///< after NMS, clipped, in pixels of the frame, by class then score
  std::size_t num_candidates = 0;            ///< boxes at or above min_confidence before NMS
  std::size_t num_dropped_empty = 0;         ///< kept by NMS but empty after clipping
  bool converted_from_grey = false;          ///< the frame was CV_8UC1 (the network saw grey as colour)
};

/// What open() found.
struct YoloOpenResult {
  Status status = Status::Ok;
  std::string reason;
  bool ok() const { return status == Status::Ok; }
  YoloHead head = YoloHead::Auto;  ///< the layout the outputs were recognised as
  int num_outputs = 0;             ///< output blobs (a Darknet net: one per [yolo] layer)
  int num_anchors = 0;             ///< candidate boxes per frame over all outputs
};

/// Buffers reused by decode_yolo_outputs from one frame to the next.
struct YoloDecodeScratch {
  std::vector<cv::Rect2d> boxes;  ///< candidates in pixels of the frame (before clipping)
  std::vector<float> scores;
  std::vector<int> class_ids;
  std::vector<cv::Rect2d> class_boxes;  ///< one class's candidates, for NMSBoxes
  std::vector<float> class_scores;
  std::vector<int> kept;
  std::vector<int> order;  ///< candidates sorted by class
};

namespace detail {

inline std::string shape_of(const cv::Mat& m) {
  std::string s = "[";
  for (int d = 0; d < m.dims; ++d) s += (d ? ", " : "") + std::to_string(m.size[d]);
  return s + "]";
}

/// Whether `m` fits `head` for `classes` classes (Auto: none of them); the anchors it holds.
inline bool head_fits(const cv::Mat& m, YoloHead head, int classes, int* anchors) {
  if (m.empty() || m.depth() != CV_32F || m.channels() != 1 || !m.isContinuous()) return false;
  if (head == YoloHead::Darknet && m.dims == 2 && m.cols == 5 + classes) {
    *anchors = m.rows;
    return true;
  }
  if (head == YoloHead::YoloV5 && m.dims == 3 && m.size[0] == 1 && m.size[2] == 5 + classes) {
    *anchors = m.size[1];
    return true;
  }
  if (head == YoloHead::YoloV8 && m.dims == 3 && m.size[0] == 1 && m.size[1] == 4 + classes) {
    *anchors = m.size[2];
    return true;
  }
  return false;
}

/// The layout of an ONNX output: YOLOv5 [1, N, 5 + C] or YOLOv8 [1, 4 + C, N]; Auto when neither.
inline YoloHead onnx_head_of(const cv::Mat& m, int classes) {
  int n = 0;
  if (head_fits(m, YoloHead::YoloV5, classes, &n)) return YoloHead::YoloV5;
  if (head_fits(m, YoloHead::YoloV8, classes, &n)) return YoloHead::YoloV8;
  return YoloHead::Auto;
}

inline std::string expected_shapes(int classes) {
  const std::string c5 = std::to_string(5 + classes), c4 = std::to_string(4 + classes);
  return "a YOLO head for " + std::to_string(classes) + " classes is CV_32F Darknet [N, " + c5 + "], YOLOv5 [1, N, " +
         c5 + "] or YOLOv8 [1, " + c4 + ", N]";
}

/// Appends one output's candidates at or above the threshold, in pixels of the frame.
inline void collect_candidates(const cv::Mat& out, YoloHead head, const YoloInputGeometry& g,
                               const YoloDetectorOptions& o, YoloDecodeScratch* s) {
  const int classes = o.num_classes;
  const bool v8 = head == YoloHead::YoloV8;
  const int n = head == YoloHead::Darknet ? out.rows : (v8 ? out.size[2] : out.size[1]);
  const int row = head == YoloHead::Darknet || head == YoloHead::YoloV5 ? 5 + classes : 1;  // step between anchors
  const int field = v8 ? n : 1;                                                              // step between fields
  const float* data = out.ptr<float>();
  // Darknet heads give normalised coordinates of the input; the ONNX exports give input pixels.
  const double norm_x = head == YoloHead::Darknet ? g.input_width : 1.0;
  const double norm_y = head == YoloHead::Darknet ? g.input_height : 1.0;
  for (int a = 0; a < n; ++a) {
    const float* p = data + static_cast<std::size_t>(a) * static_cast<std::size_t>(row);
    const float* cls = p + static_cast<std::size_t>(v8 ? 4 : 5) * static_cast<std::size_t>(field);
    int best = 0;
    float best_score = cls[0];
    for (int c = 1; c < classes; ++c) {
      const float v = cls[static_cast<std::size_t>(c) * static_cast<std::size_t>(field)];
      if (v > best_score) {
        best_score = v;
        best = c;
      }
    }
    // Darknet (OpenCV's region layer) has already multiplied the class scores by the objectness.
    const bool times_objectness = head == YoloHead::YoloV5 || (head == YoloHead::Darknet && o.reapply_objectness);
    const float confidence = times_objectness ? p[4] * best_score : best_score;
    if (!(confidence >= o.min_confidence)) continue;  // NaN never passes
    const double cx = p[0] * norm_x, cy = p[field] * norm_y, w = p[2 * field] * norm_x, h = p[3 * field] * norm_y;
    const double x0 = (cx - w / 2 - g.offset_x) / g.scale_x, y0 = (cy - h / 2 - g.offset_y) / g.scale_y;
    const double x1 = (cx + w / 2 - g.offset_x) / g.scale_x, y1 = (cy + h / 2 - g.offset_y) / g.scale_y;
    if (!(std::isfinite(x0) && std::isfinite(y0) && std::isfinite(x1) && std::isfinite(y1))) continue;
    s->boxes.emplace_back(x0, y0, x1 - x0, y1 - y0);
    s->scores.push_back(confidence);
    s->class_ids.push_back(best);
  }
}

/// A Darknet network's outputs against its cfg: one per [yolo] layer, each holding a whole number of
/// grid cells of that layer's anchors.
inline bool outputs_fit_layout(const std::vector<cv::Mat>& outputs, const DarknetLayout& layout, std::string* why) {
  if (outputs.size() != layout.heads.size()) {
    *why = std::to_string(outputs.size()) + " outputs for the cfg's " + std::to_string(layout.heads.size()) + " [yolo] layers";
    return false;
  }
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    const int anchors = layout.heads[k].anchors;
    if (outputs[k].dims != 2 || outputs[k].rows == 0 || outputs[k].rows % anchors != 0) {
      *why = "output " + std::to_string(k) + " has shape " + shape_of(outputs[k]) + ", not whole grid cells of " +
             std::to_string(anchors) + " anchors";
      return false;
    }
  }
  return true;
}

}  // namespace detail

/// Raw network outputs -> detections: candidates with objectness x class score >= min_confidence, NMS
/// per class at nms_iou (cv::dnn::NMSBoxes), boxes mapped back through `geometry`, clipped to the frame
/// and dropped when empty. `head` must be Darknet, YoloV5 or YoloV8, and every output must have its
/// shape (InvalidInput naming the output otherwise). Writes `*out`, reusing its and `scratch`'s buffers.
inline void decode_yolo_outputs(const std::vector<cv::Mat>& outputs, YoloHead head, const YoloInputGeometry& geometry,
                                const YoloDetectorOptions& options, YoloDecodeScratch* scratch,
                                YoloDetectorResult* out) {
  YoloDetectorResult& r = *out;
  r.status = Status::Ok;
  r.reason.clear();
  r.detections.clear();
  r.num_candidates = r.num_dropped_empty = 0;
  auto fail = [&](const std::string& why) {
    r.status = Status::InvalidInput;
    r.reason = "yolo_detector: " + why;
  };
  if (options.validate(&r.reason) != Status::Ok) return fail(r.reason);
  if (head == YoloHead::Auto) return fail("decode_yolo_outputs needs the head's layout (Darknet, YoloV5 or YoloV8)");
  if (geometry.image_width <= 0 || geometry.image_height <= 0 || geometry.input_width <= 0 ||
      geometry.input_height <= 0 || !(geometry.scale_x > 0) || !(geometry.scale_y > 0))
    return fail("the input geometry needs positive image and input sizes and scales");
  if (outputs.empty()) return fail("the network gave no output");
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    int anchors = 0;
    if (!detail::head_fits(outputs[k], head, options.num_classes, &anchors))
      return fail("output " + std::to_string(k) + " has shape " + detail::shape_of(outputs[k]) + " (type " +
                  std::to_string(outputs[k].type()) + "), not a " + to_string(head) + " head: " +
                  detail::expected_shapes(options.num_classes));
  }
  YoloDecodeScratch& s = *scratch;
  s.boxes.clear();
  s.scores.clear();
  s.class_ids.clear();
  for (const cv::Mat& o : outputs) detail::collect_candidates(o, head, geometry, options, &s);
  r.num_candidates = s.boxes.size();

  // NMS one class at a time: a person box never suppresses the chair it overlaps.
  s.order.resize(s.boxes.size());
  for (std::size_t i = 0; i < s.order.size(); ++i) s.order[i] = static_cast<int>(i);
  // By class, then index: std::sort with the tie broken needs no temporary buffer (std::stable_sort does).
  std::sort(s.order.begin(), s.order.end(), [&](int a, int b) {
    const int ca = s.class_ids[static_cast<std::size_t>(a)], cb = s.class_ids[static_cast<std::size_t>(b)];
    return ca != cb ? ca < cb : a < b;
  });
  for (std::size_t begin = 0; begin < s.order.size();) {
    const int cls = s.class_ids[static_cast<std::size_t>(s.order[begin])];
    std::size_t end = begin;
    s.class_boxes.clear();
    s.class_scores.clear();
    for (; end < s.order.size() && s.class_ids[static_cast<std::size_t>(s.order[end])] == cls; ++end) {
      const std::size_t i = static_cast<std::size_t>(s.order[end]);
      s.class_boxes.push_back(s.boxes[i]);
      s.class_scores.push_back(s.scores[i]);
    }
    begin = end;
    s.kept.clear();
    // NMSBoxes keeps scores strictly above its threshold, which must be >= 0: the candidates already
    // passed >= min_confidence, so 0 drops only zero scores (possible only with min_confidence 0).
    try {
      cv::dnn::NMSBoxes(s.class_boxes, s.class_scores, 0.f, options.nms_iou, s.kept);
    } catch (const cv::Exception& e) {
      r.detections.clear();
      return fail(std::string("NMS failed: ") + e.what());
    }
    for (const int k : s.kept) {
      const cv::Rect2d& b = s.class_boxes[static_cast<std::size_t>(k)];
      const Box<float> px = Box<float>{float(b.x), float(b.y), float(b.x + b.width), float(b.y + b.height)}.clipped(
          geometry.image_width, geometry.image_height);
      if (!(px.x1 > px.x0) || !(px.y1 > px.y0)) {
        ++r.num_dropped_empty;
        continue;
      }
      r.detections.push_back(Detection<float>{px, cls, s.class_scores[static_cast<std::size_t>(k)]});
    }
  }
}

/// A YOLO network on OpenCV DNN (CPU backend). Not thread-safe: one detector per thread. After the
/// first frame of a size its own buffers (resized frame, blob, candidates, result) are reused; OpenCV's
/// forward() and NMSBoxes still allocate inside.
class YoloDetector {
 public:
  /// Loads the network and runs it once on a blank input to check its outputs are a YOLO head (and to
  /// allocate its buffers). The files are read under the file-opening rule of core/text_file.hpp
  /// (regular files, not the kernel's, never waited on; cfg at most kMaxYoloCfgBytes, weights and ONNX at
  /// most kMaxYoloModelBytes) and OpenCV parses the bytes. A Darknet cfg is followed layer by layer
  /// (darknet_layout.hpp): the weights must have exactly the size its layers need. Any failure leaves
  /// the detector closed, with the reason: IoError for a file that is missing, not regular, the kernel's
  /// or over its cap; InvalidInput for bad options, a cfg without weights, an unknown model extension,
  /// weights of another size than the cfg's layers need, or outputs that are not its YOLO heads;
  /// ParseError for a cfg whose layers cannot be followed or a model OpenCV cannot read.
  YoloOpenResult open(const YoloDetectorOptions& options) {
    opened_ = YoloOpenResult{};
    net_ = cv::dnn::Net();
    options_ = options;
    YoloOpenResult& r = opened_;
    auto fail = [&](Status st, const std::string& why) {
      r.status = st;
      r.reason = "yolo_detector: " + why;
      net_ = cv::dnn::Net();
      return r;
    };
    std::string why;
    if (options.validate(&why) != Status::Ok) return fail(Status::InvalidInput, why);
    if (!model_kind_fits(options, &why)) return fail(Status::InvalidInput, why);
    const bool darknet = ends_with(options.model, ".cfg");
    DarknetLayout layout;
    const Status read = read_network(options, darknet, &layout, &why);
    if (read != Status::Ok) return fail(read, why);
    if (!warm_up(options, &why)) return fail(Status::ParseError, why);
    if (outputs_.empty()) return fail(Status::InvalidInput, options.model + ": the network has no output");
    if (darknet) {
      head_ = YoloHead::Darknet;
      // A cfg without [yolo] layers is reported below with its outputs' shapes.
      if (!layout.heads.empty() && !detail::outputs_fit_layout(outputs_, layout, &why))
        return fail(Status::InvalidInput, options.model + ": " + why);
    } else if (!select_onnx_heads(options, &why)) {
      return fail(Status::ParseError, why);
    }
    int anchors = 0;
    for (std::size_t k = 0; k < outputs_.size(); ++k) {
      int n = 0;
      if (head_ == YoloHead::Auto || !detail::head_fits(outputs_[k], head_, options.num_classes, &n))
        return fail(Status::InvalidInput, options.model + ": output " + std::to_string(k) + " has shape " +
                                              detail::shape_of(outputs_[k]) + ", not a YOLO head (" +
                                              detail::expected_shapes(options.num_classes) + ")");
      anchors += n;
    }
    r.head = head_;
    r.num_outputs = static_cast<int>(outputs_.size());
    r.num_anchors = anchors;
    return r;
  }

  bool ok() const { return opened_.ok() && !net_.empty(); }
  const YoloOpenResult& opened() const { return opened_; }
  const YoloDetectorOptions& options() const { return options_; }
  YoloHead head() const { return head_; }

  /// Detections on one frame: CV_8UC3 BGR (the detector was trained on colour), or CV_8UC1 grey, which
  /// is replicated to three channels (converted_from_grey; expect fewer boxes than on colour). An empty
  /// frame, another type or a closed detector give InvalidInput and no detections. The returned reference
  /// is valid until the next detect(); its buffers are reused.
  const YoloDetectorResult& detect(const cv::Mat& frame) {
    detect(frame, &result_);
    return result_;
  }

  /// Same, into `*out` (reusing its buffers).
  void detect(const cv::Mat& frame, YoloDetectorResult* out) {
    YoloDetectorResult& r = *out;
    r.detections.clear();
    r.num_candidates = r.num_dropped_empty = 0;
    r.converted_from_grey = false;
    auto fail = [&](const std::string& why) {
      r.status = Status::InvalidInput;
      r.reason = "yolo_detector: " + why;
    };
    if (!ok()) return fail("not open (" + (opened_.reason.empty() ? std::string("open() was not called") : opened_.reason) + ")");
    if (frame.empty()) return fail("the frame is empty");
    if (frame.dims != 2 || (frame.type() != CV_8UC3 && frame.type() != CV_8UC1))
      return fail("the frame must be CV_8UC3 (BGR) or CV_8UC1 (grey), got type " + std::to_string(frame.type()) +
                  " with " + std::to_string(frame.channels()) + " channels");
    const cv::Mat* bgr = &frame;
    if (frame.type() == CV_8UC1) {
      cv::cvtColor(frame, grey_bgr_, cv::COLOR_GRAY2BGR);
      bgr = &grey_bgr_;
      r.converted_from_grey = true;
    }
    const YoloInputGeometry g =
        options_.resize == YoloResize::Letterbox
            ? YoloInputGeometry::letterbox(frame.cols, frame.rows, options_.input_width, options_.input_height)
            : YoloInputGeometry::plain(frame.cols, frame.rows, options_.input_width, options_.input_height);
    try {
      fill_blob(*bgr, g);
      net_.setInput(blob_);
      net_.forward(outputs_, out_names_);
    } catch (const cv::Exception& e) {
      r.status = Status::ParseError;
      r.reason = "yolo_detector: the network failed on the frame: " + first_line(e.what());
      return;
    }
    const bool grey = r.converted_from_grey;
    decode_yolo_outputs(outputs_, head_, g, options_, &scratch_, &r);
    r.converted_from_grey = grey;
  }

 private:
  /// False, with the reason, when the model is neither a Darknet cfg nor an ONNX file, or its weights or
  /// head option do not go with its kind.
  static bool model_kind_fits(const YoloDetectorOptions& options, std::string* why) {
    auto bad = [&](std::string reason) {
      *why = std::move(reason);
      return false;
    };
    if (options.model.empty()) return bad("options.model is empty (a Darknet .cfg or an .onnx)");
    const bool darknet = ends_with(options.model, ".cfg");
    const bool onnx = ends_with(options.model, ".onnx");
    if (!darknet && !onnx) return bad(options.model + ": unknown model type (expected a Darknet .cfg or an .onnx)");
    if (darknet && options.weights.empty())
      return bad(text::quote_path(options.model) + ": a Darknet cfg needs its .weights file (options.weights is empty)");
    if (onnx && !options.weights.empty())
      return bad(text::quote_path(options.model) +
                 ": an ONNX model holds its own weights (options.weights must be empty)");
    if (darknet && (options.head == YoloHead::YoloV5 || options.head == YoloHead::YoloV8))
      return bad(text::quote_path(options.model) + ": a Darknet cfg has Darknet heads, not " + to_string(options.head));
    if (onnx && options.head == YoloHead::Darknet)
      return bad(text::quote_path(options.model) + ": an ONNX export has a YOLOv5 or YOLOv8 head, not darknet");
    return true;
  }

  /// Reads the model files under the file-opening rule and has OpenCV parse the bytes into net_ (it never
  /// opens a path itself, so a FIFO, a device or a file swapped after the check never reaches it); a
  /// Darknet cfg's layers into `layout`, checked against the weights' size.
  Status read_network(const YoloDetectorOptions& options, bool darknet, DarknetLayout* layout, std::string* why) {
    std::vector<char> model_bytes, weights_bytes;
    if (!read_model_file(options.model, darknet ? kMaxYoloCfgBytes : kMaxYoloModelBytes, &model_bytes, why) ||
        (darknet && !read_model_file(options.weights, kMaxYoloModelBytes, &weights_bytes, why)))
      return Status::IoError;
    if (darknet) {
      const Status st = check_darknet_files(options, model_bytes, weights_bytes, layout, why);
      if (st != Status::Ok) return st;
    }
    try {
      net_ = darknet ? cv::dnn::readNetFromDarknet(model_bytes.data(), model_bytes.size(), weights_bytes.data(),
                                                   weights_bytes.size())
                     : cv::dnn::readNetFromONNX(model_bytes.data(), model_bytes.size());
    } catch (const cv::Exception& e) {
      *why = options.model + ": OpenCV cannot read the model: " + first_line(e.what());
      return Status::ParseError;
    } catch (const std::exception& e) {
      *why = options.model + ": OpenCV cannot read the model: " + first_line(e.what());
      return Status::ParseError;
    }
    if (net_.empty()) {
      *why = options.model + ": OpenCV read an empty network";
      return Status::ParseError;
    }
    return Status::Ok;
  }

  /// Runs the network once on a blank input of the options' size: checks it runs, fills outputs_ for the
  /// head checks and allocates the network's buffers. False, with the reason, when OpenCV fails.
  bool warm_up(const YoloDetectorOptions& options, std::string* why) {
    try {
      net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
      net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
      out_names_ = net_.getUnconnectedOutLayersNames();
      const int shape[4] = {1, 3, options.input_height, options.input_width};
      blob_.create(4, shape, CV_32F);
      blob_.setTo(0);
      net_.setInput(blob_);
      net_.forward(outputs_, out_names_);
    } catch (const cv::Exception& e) {
      *why = options.model + ": the network does not run on a " + std::to_string(options.input_width) + " x " +
             std::to_string(options.input_height) + " input: " + first_line(e.what());
      return false;
    }
    return true;
  }

  /// The ONNX outputs that are a YOLO head (of options.head, or the first kind recognised when Auto) become
  /// the outputs computed: some YOLOv5 exports keep the raw per-scale maps ([1, 3, H, W, 85]) beside the
  /// decoded output. With none, the first output stays, for its shape to be reported. False, with the
  /// reason, when the network does not run on the narrowed outputs.
  bool select_onnx_heads(const YoloDetectorOptions& options, std::string* why) {
    head_ = options.head;
    std::vector<cv::String> heads;
    for (std::size_t k = 0; k < outputs_.size(); ++k) {
      const YoloHead h = head_ != YoloHead::Auto ? head_ : detail::onnx_head_of(outputs_[k], options.num_classes);
      int n = 0;
      if (h == YoloHead::Auto || !detail::head_fits(outputs_[k], h, options.num_classes, &n)) continue;
      head_ = h;
      heads.push_back(out_names_[k]);
    }
    if (heads.empty()) heads.push_back(out_names_.front());  // reported below with its shape
    if (heads.size() != out_names_.size()) {
      out_names_ = heads;
      try {
        net_.forward(outputs_, out_names_);
      } catch (const cv::Exception& e) {
        *why = options.model + ": the network does not run: " + first_line(e.what());
        return false;
      }
    }
    return true;
  }

  static bool ends_with(const std::string& s, const char* suffix) {
    const std::string x(suffix);
    if (s.size() < x.size()) return false;
    for (std::size_t k = 0; k < x.size(); ++k) {
      const char c = s[s.size() - x.size() + k];
      if ((c >= 'A' && c <= 'Z' ? char(c - 'A' + 'a') : c) != x[k]) return false;
    }
    return true;
  }
  /// The whole file under the file-opening rule (text::InputFile: regular, not the kernel's, at most max_bytes).
  static bool read_model_file(const std::string& path, std::uint64_t max_bytes, std::vector<char>* bytes,
                              std::string* why) {
    text::InputFile file;
    if (!file.open(path, max_bytes, why)) return false;
    bytes->resize(static_cast<std::size_t>(file.size()));
    std::size_t at = 0;
    while (true) {
      char chunk[1 << 16];
      const long got = file.read(chunk, sizeof chunk);
      if (got == 0) break;
      if (got < 0 || at + static_cast<std::size_t>(got) > bytes->size()) {
        *why = text::quote_path(path) + (got == -1 ? ": read error" : ": changed size while read");
        return false;
      }
      std::memcpy(bytes->data() + at, chunk, static_cast<std::size_t>(got));
      at += static_cast<std::size_t>(got);
    }
    if (at != bytes->size()) {
      *why = text::quote_path(path) + ": changed size while read";
      return false;
    }
    return true;
  }

  /// The cfg's layout (darknet_layout) and the weights file's size against it: exactly its header and 4
  /// bytes per float of every convolution. (The heads' classes are checked on the outputs' shapes.)
  static Status check_darknet_files(const YoloDetectorOptions& options, const std::vector<char>& cfg,
                                    const std::vector<char>& weights, DarknetLayout* layout, std::string* why) {
    const std::string cfg_name = text::quote_path(options.model), weights_name = text::quote_path(options.weights);
    if (!darknet_layout(std::string_view(cfg.data(), cfg.size()), layout, why)) {
      *why = cfg_name + ": " + *why;
      return Status::ParseError;
    }
    std::int32_t version[2] = {0, 0};
    if (weights.size() >= sizeof version) std::memcpy(version, weights.data(), sizeof version);
    const std::uint64_t need = layout->weights_bytes(version[0], version[1]);
    if (weights.size() != need) {
      *why = weights_name + ": " + std::to_string(weights.size()) + " bytes, where the layers of " + cfg_name +
             " need " + std::to_string(need) + (weights.size() < need ? " (truncated?)" : " (padded, or another network's?)");
      return Status::InvalidInput;
    }
    return Status::Ok;
  }
  static std::string first_line(const char* what) {
    std::string s(what ? what : "");
    // OpenCV's messages start with a newline and "OpenCV(4.x) file:line: error: ..."
    const std::size_t start = s.find_first_not_of("\n ");
    if (start == std::string::npos) return "unknown error";
    const std::size_t end = s.find('\n', start);
    return s.substr(start, end == std::string::npos ? std::string::npos : end - start);
  }

  /// Frame -> NCHW float blob in [0, 1], into buffers kept from one frame to the next (as
  /// cv::dnn::blobFromImage(frame, 1/255, size, 0, swap_rb) but without its per-call images).
  void fill_blob(const cv::Mat& bgr, const YoloInputGeometry& g) {
    const int in_w = options_.input_width, in_h = options_.input_height;
    if (options_.resize == YoloResize::Letterbox) {
      input_.create(in_h, in_w, CV_8UC3);
      input_.setTo(cv::Scalar::all(options_.letterbox_fill));
      // checked: letterbox() sets the offsets from whole pixels in [0, input size]
      const cv::Rect inner(static_cast<int>(g.offset_x), static_cast<int>(g.offset_y), g.scaled_width(), g.scaled_height());
      cv::Mat roi = input_(inner);
      cv::resize(bgr, roi, inner.size(), 0, 0, cv::INTER_LINEAR);
    } else {
      cv::resize(bgr, input_, cv::Size(in_w, in_h), 0, 0, cv::INTER_LINEAR);
    }
    if (options_.swap_rb) cv::cvtColor(input_, rgb_, cv::COLOR_BGR2RGB);
    const cv::Mat& src = options_.swap_rb ? rgb_ : input_;
    src.convertTo(scaled_, CV_32F, 1.0 / 255.0);
    const int shape[4] = {1, 3, in_h, in_w};
    blob_.create(4, shape, CV_32F);
    float* base = blob_.ptr<float>();
    const std::size_t plane = static_cast<std::size_t>(in_w) * static_cast<std::size_t>(in_h);
    for (int c = 0; c < 3; ++c) planes_[c] = cv::Mat(in_h, in_w, CV_32F, base + static_cast<std::size_t>(c) * plane);
    cv::split(scaled_, planes_);  // writes into the blob's planes (same size and type: no allocation)
  }

  YoloDetectorOptions options_;
  YoloOpenResult opened_{Status::InvalidInput, "yolo_detector: open() was not called"};
  YoloHead head_ = YoloHead::Auto;
  cv::dnn::Net net_;
  std::vector<cv::String> out_names_;
  std::vector<cv::Mat> outputs_;
  cv::Mat grey_bgr_, input_, rgb_, scaled_, blob_;
  cv::Mat planes_[3];
  YoloDecodeScratch scratch_;
  YoloDetectorResult result_;
};

}  // namespace cv_adapter
}  // namespace dyncull
