// libFuzzer target: per-frame detection JSON (eval/yolo_json.hpp parse_yolo_json) in float and double,
// with the default bounds and with tight ones, under a comma-decimal C locale when one is installed.
// An accepted frame holds only finite boxes, confidences and stamps; a refused one is a ParseError with
// a short, printable reason that names the source; tight bounds never accept what the default ones refuse.
#include "dyncull/eval/yolo_json.hpp"

#include "fuzz_input.hpp"

#include <clocale>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace {

using namespace dyncull;

template <class T>
eval::YoloJsonFrame<T> check(std::string_view text, const eval::YoloJsonOptions& options) {
  eval::YoloJsonFrame<T> f = eval::parse_yolo_json<T>(text, "fuzz.json", options);
  // Reasons are printable text: bytes of the input are shown by their code, never copied.
  for (char c : f.reason) DYNCULL_FUZZ_CHECK(c >= 0x20 && c < 0x7f);
  if (!f.ok()) {
    DYNCULL_FUZZ_CHECK(f.status == Status::ParseError);
    DYNCULL_FUZZ_CHECK(f.reason.rfind("fuzz.json: ", 0) == 0);
    // Reasons quote at most a short token, never the input (keys echoed are the reader's own).
    DYNCULL_FUZZ_CHECK(f.reason.size() < 400);
    DYNCULL_FUZZ_CHECK(f.detections.empty());
    return f;
  }
  DYNCULL_FUZZ_CHECK(f.reason.empty());
  DYNCULL_FUZZ_CHECK(f.frame_id >= 0 && f.frame_id <= 1000000000000000LL);
  DYNCULL_FUZZ_CHECK(std::isfinite(f.timestamp));
  DYNCULL_FUZZ_CHECK(f.detections.size() <= options.max_detections);
  for (const Detection<T>& d : f.detections) {
    DYNCULL_FUZZ_CHECK(d.box.finite());
    DYNCULL_FUZZ_CHECK(std::isfinite(d.confidence));
    DYNCULL_FUZZ_CHECK(d.class_id >= 0 && d.class_id <= 1000000);
  }
  return f;
}

template <class T>
void check_both(std::string_view text) {
  const eval::YoloJsonFrame<T> loose = check<T>(text, eval::YoloJsonOptions{});
  eval::YoloJsonOptions tight;
  tight.max_depth = 3;
  tight.max_detections = 4;
  tight.max_string_chars = 16;
  tight.max_bytes = 512;
  const eval::YoloJsonFrame<T> strict = check<T>(text, tight);
  if (strict.ok()) {
    // Tighter bounds only refuse more; what they accept reads the same.
    DYNCULL_FUZZ_CHECK(loose.ok());
    DYNCULL_FUZZ_CHECK(loose.frame_id == strict.frame_id && loose.timestamp == strict.timestamp);
    DYNCULL_FUZZ_CHECK(loose.detections.size() == strict.detections.size());
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // The reader must not depend on the C locale: run under a comma-decimal one when available.
  if (!std::setlocale(LC_ALL, "de_DE.UTF-8"))
    std::fprintf(stderr, "yolo_json_fuzz: de_DE.UTF-8 not installed, C locale\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  check_both<float>(text);
  check_both<double>(text);
  return 0;
}
