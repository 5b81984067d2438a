// libFuzzer target: YOLO label text (culling/detections.hpp parse_yolo_lines) in float and double
// under a comma-decimal C locale when one is installed, then the parsed boxes through
// convert_yolo_detections with an image size and letterbox from the input: kept boxes are finite,
// ordered and inside the image.
#include "dyncull/culling/detections.hpp"

#include "fuzz_input.hpp"

#include <clocale>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace {

using namespace dyncull;

template <class T>
void check(std::string_view text, int width, int height, const Letterbox<T>& letterbox) {
  const YoloParseResult<T> r = parse_yolo_lines<T>(text, "fuzz");
  DYNCULL_FUZZ_CHECK(r.boxes.size() == r.line_of_box.size());
  DYNCULL_FUZZ_CHECK(r.errors.size() <= kYoloMaxListedErrors);
  DYNCULL_FUZZ_CHECK(r.errors.size() <= r.num_bad_lines);
  DYNCULL_FUZZ_CHECK(r.ok() == (r.num_bad_lines == 0));
  DYNCULL_FUZZ_CHECK(r.reason.size() < 300);
  DYNCULL_FUZZ_CHECK(r.reason.find('\0') == std::string::npos);
  for (const YoloParseError& e : r.errors) DYNCULL_FUZZ_CHECK(e.line >= 1 && e.message.size() < 250);
  for (const YoloBox<T>& b : r.boxes) DYNCULL_FUZZ_CHECK(b.class_id >= 0 && b.class_id <= 1000000);

  const DetectionsResult<T> c = convert_yolo_detections<T>(r.boxes, width, height, DetectionOptions<T>{}, letterbox);
  DYNCULL_FUZZ_CHECK(c.ok());
  DYNCULL_FUZZ_CHECK(c.rejections.size() == r.boxes.size());
  DYNCULL_FUZZ_CHECK(c.detections.size() == c.num_kept && c.source_index.size() == c.num_kept);
  for (const Detection<T>& d : c.detections) {
    DYNCULL_FUZZ_CHECK(d.box.finite());
    DYNCULL_FUZZ_CHECK(d.box.x0 >= T(0) && d.box.y0 >= T(0));
    DYNCULL_FUZZ_CHECK(d.box.x1 <= T(width - 1) && d.box.y1 <= T(height - 1));
    DYNCULL_FUZZ_CHECK(d.box.x0 <= d.box.x1 && d.box.y0 <= d.box.y1);
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (!std::setlocale(LC_ALL, "de_DE.UTF-8")) std::fprintf(stderr, "yolo_fuzz: de_DE.UTF-8 not installed, C locale\n");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The first 8 bytes choose the image and letterbox; the rest is the text.
  fuzz::Input in(data, size < 8 ? size : 8);
  const int width = in.range(1, 4096), height = in.range(1, 4096);
  const bool boxed = in.flag();
  const int in_w = in.range(0, 1280), in_h = in_w;
  const std::size_t skip = size < 8 ? size : 8;
  const std::string_view text(reinterpret_cast<const char*>(data) + skip, size - skip);
  check<float>(text, width, height,
               boxed ? Letterbox<float>::centred(width, height, in_w, in_h) : Letterbox<float>{});
  check<double>(text, width, height,
                boxed ? Letterbox<double>::centred(width, height, in_w, in_h) : Letterbox<double>{});
  return 0;
}
