// libFuzzer target: a sequence's detections folder (eval/sequence.hpp read_sequence_detections) of
// per-frame JSON files under a comma-decimal C locale when one is installed. The first bytes give the
// frames' stamps (1 to 8 frames on a 1/64 s grid); the rest, split at NUL bytes, is written as up to 8
// files NNNNNN.json. Invariants: a short printable reason and notes; an accepted read has one entry per
// frame, boxes finite and inside the image, has_file and the counts consistent.
#include "dyncull/eval/sequence.hpp"

#include "fuzz_input.hpp"

#include <algorithm>
#include <clocale>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

namespace {

using namespace dyncull;

std::string& scratch() {
  static std::string dir;
  return dir;
}

void remove_scratch() {
  std::error_code ec;
  std::filesystem::remove_all(scratch(), ec);
}

void check_text(const std::string& s) {
  DYNCULL_FUZZ_CHECK(s.size() < 1200);
  for (char c : s) DYNCULL_FUZZ_CHECK(c >= 0x20 && c < 0x7f);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (!std::setlocale(LC_ALL, "de_DE.UTF-8"))
    std::fprintf(stderr, "detections_fuzz: de_DE.UTF-8 not installed, C locale\n");
  scratch() = (std::filesystem::temp_directory_path() / ("dyncull_detections_fuzz_" + std::to_string(::getpid()))).string();
  std::atexit(remove_scratch);  // libFuzzer ends its run through exit()
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  eval::SequenceIndex s;
  const int frames = in.range(1, 8);
  for (int k = 0; k < frames; ++k) {
    eval::SequenceFrame f;
    f.timestamp = 10.0 + in.range(0, 255) / 64.0;
    s.frames.push_back(f);
  }
  std::sort(s.frames.begin(), s.frames.end(),
            [](const eval::SequenceFrame& a, const eval::SequenceFrame& b) { return a.timestamp < b.timestamp; });
  const std::size_t used = static_cast<std::size_t>(4 * (1 + frames));  // each range() reads 4 bytes
  std::string_view rest = size > used ? std::string_view(reinterpret_cast<const char*>(data) + used, size - used)
                                      : std::string_view();
  std::error_code ec;
  std::filesystem::remove_all(scratch(), ec);
  std::filesystem::create_directories(scratch());
  int files = 0;
  while (files < 8 && !rest.empty()) {
    const std::size_t cut = rest.find('\0');
    char name[32];
    std::snprintf(name, sizeof name, "/%06d.json", files++);
    const std::string_view body = rest.substr(0, cut);
    std::ofstream(scratch() + name, std::ios::binary).write(body.data(), static_cast<std::streamsize>(body.size()));
    rest = cut == std::string_view::npos ? std::string_view() : rest.substr(cut + 1);
  }
  if (files == 0) return 0;  // a folder without JSON is read as YOLO text: another reader
  const eval::SequenceDetections d = eval::read_sequence_detections(scratch(), s, 640, 480);
  check_text(d.reason);
  for (const std::string& n : d.notes.first) check_text(n);
  if (!d.ok()) {
    DYNCULL_FUZZ_CHECK(d.status == Status::ParseError || d.status == Status::IoError);
    return 0;
  }
  DYNCULL_FUZZ_CHECK(d.per_frame.size() == s.frames.size() && d.has_file.size() == s.frames.size());
  std::size_t with = 0;
  for (std::size_t i = 0; i < s.frames.size(); ++i) {
    with += d.has_file[i];
    if (!d.has_file[i]) DYNCULL_FUZZ_CHECK(d.per_frame[i].empty());
    for (const Detection<float>& b : d.per_frame[i]) {
      DYNCULL_FUZZ_CHECK(b.box.finite() && std::isfinite(b.confidence));
      DYNCULL_FUZZ_CHECK(b.box.x0 >= 0 && b.box.y0 >= 0 && b.box.x1 <= 640 && b.box.y1 <= 480);
    }
  }
  DYNCULL_FUZZ_CHECK(with == d.frames_with_file);
  DYNCULL_FUZZ_CHECK(d.files_unmatched <= static_cast<std::size_t>(files));
  return 0;
}
