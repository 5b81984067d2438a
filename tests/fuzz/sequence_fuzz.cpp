// libFuzzer target: the sequence folder's text readers (eval/sequence.hpp) under a comma-decimal C locale
// when one is installed. The first byte picks the reader:
//   0: camera.txt (read_camera_file);  1: a --camera spec (camera_from_spec, never a path);
//   2: rgb.txt and depth.txt, split at the first NUL byte (read_sequence, association included);
//   3: two small stamp lists decoded from the bytes, associate() against associate.py's literal O(n m)
//      algorithm (quantised stamps make exact ties and shared windows common).
// Invariants: reasons and notes are short printable text; an accepted camera passes the camera check;
// an accepted sequence is sorted, each depth partner within the window and used once.
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
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
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

void check_text(const std::string& s, std::size_t max_chars) {
  DYNCULL_FUZZ_CHECK(s.size() < max_chars);
  for (char c : s) DYNCULL_FUZZ_CHECK(c >= 0x20 && c < 0x7f);
}

void write(const std::string& path, std::string_view text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(text.data(), static_cast<std::streamsize>(text.size()));
}

void check_camera(const eval::CameraResult& c) {
  check_text(c.reason, 600);
  if (!c.ok()) {
    DYNCULL_FUZZ_CHECK(c.status == Status::ParseError || c.status == Status::InvalidInput || c.status == Status::IoError);
    return;
  }
  DYNCULL_FUZZ_CHECK(c.camera.validate() == Status::Ok);
  DYNCULL_FUZZ_CHECK(std::isfinite(c.camera.fx) && std::isfinite(c.camera.cy) && c.camera.fx > 0);
}

void check_lists(std::string_view text, double max_difference_s) {
  const std::size_t split = text.find('\0');
  write(scratch() + "/rgb.txt", text.substr(0, split));
  write(scratch() + "/depth.txt", split == std::string_view::npos ? std::string_view() : text.substr(split + 1));
  eval::SequenceOptions o;
  o.check_files = false;
  o.max_difference_s = max_difference_s;
  const eval::SequenceIndex s = eval::read_sequence(scratch(), o);
  check_text(s.reason, 1200);
  for (const std::string& n : s.notes.first) check_text(n, 1200);
  if (!s.ok()) {
    DYNCULL_FUZZ_CHECK(s.status == Status::ParseError || s.status == Status::TooFewPoints);
    return;
  }
  std::set<double> depth_used;
  std::size_t without = 0;
  for (std::size_t i = 0; i < s.frames.size(); ++i) {
    const eval::SequenceFrame& f = s.frames[i];
    DYNCULL_FUZZ_CHECK(std::isfinite(f.timestamp));
    if (i > 0) DYNCULL_FUZZ_CHECK(s.frames[i - 1].timestamp < f.timestamp);
    if (!f.has_depth()) {
      ++without;
      continue;
    }
    DYNCULL_FUZZ_CHECK(std::abs(f.timestamp - f.depth_timestamp) < max_difference_s);
    DYNCULL_FUZZ_CHECK(depth_used.insert(f.depth_timestamp).second);
  }
  DYNCULL_FUZZ_CHECK(without == s.frames_without_depth);
}

// associate.py, literally: every pair in the window, sorted by (difference, a, b), taken greedily.
std::vector<std::pair<double, double>> associate_py(std::vector<double> a, std::vector<double> b, double offset,
                                                    double max_difference) {
  std::sort(a.begin(), a.end());
  a.erase(std::unique(a.begin(), a.end()), a.end());
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end()), b.end());
  std::vector<std::tuple<double, double, double>> candidates;
  for (double x : a)
    for (double y : b)
      if (std::abs(x - (y + offset)) < max_difference) candidates.emplace_back(std::abs(x - (y + offset)), x, y);
  std::sort(candidates.begin(), candidates.end());
  std::set<double> used_a, used_b;
  std::vector<std::pair<double, double>> out;
  for (const auto& c : candidates) {
    if (used_a.count(std::get<1>(c)) || used_b.count(std::get<2>(c))) continue;
    used_a.insert(std::get<1>(c));
    used_b.insert(std::get<2>(c));
    out.emplace_back(std::get<1>(c), std::get<2>(c));
  }
  std::sort(out.begin(), out.end());
  return out;
}

void check_association(fuzz::Input& in) {
  const double quantum = in.flag() ? 1.0 / 64 : 1e-3 * (1 + in.range(0, 9));
  eval::AssociationOptions o;
  o.max_difference_s = quantum * in.range(1, 40);
  o.offset_s = in.flag() ? 0.0 : quantum * in.range(-20, 20);
  std::vector<double> a(static_cast<std::size_t>(in.range(0, 48))), b(static_cast<std::size_t>(in.range(0, 48)));
  for (double& t : a) t = 100.0 + quantum * in.range(0, 200);
  for (double& t : b) t = 100.0 + quantum * in.range(0, 200);
  const eval::AssociationResult r = eval::associate(a, b, o);
  const auto expected = associate_py(a, b, o.offset_s, o.max_difference_s);
  DYNCULL_FUZZ_CHECK(r.size() == expected.size());
  DYNCULL_FUZZ_CHECK(r.ok() == !expected.empty());
  for (std::size_t k = 0; k < r.size(); ++k) {
    DYNCULL_FUZZ_CHECK(a[r.first[k]] == expected[k].first);
    DYNCULL_FUZZ_CHECK(b[r.second[k]] == expected[k].second);
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (!std::setlocale(LC_ALL, "de_DE.UTF-8"))
    std::fprintf(stderr, "sequence_fuzz: de_DE.UTF-8 not installed, C locale\n");
  scratch() = (std::filesystem::temp_directory_path() / ("dyncull_sequence_fuzz_" + std::to_string(::getpid()))).string();
  std::filesystem::create_directories(scratch());
  std::atexit(remove_scratch);  // libFuzzer ends its run through exit()
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 4) {
    case 0:
      write(scratch() + "/camera.txt", text);
      check_camera(eval::read_camera_file(scratch() + "/camera.txt"));
      break;
    case 1:
      if (text.find('/') == std::string_view::npos) check_camera(eval::camera_from_spec(std::string(text)));
      break;
    case 2: {
      const double windows[4] = {0.02, 0.001, 0.5, 10.0};
      check_lists(text.empty() ? text : text.substr(1), windows[text.empty() ? 0 : static_cast<std::uint8_t>(text[0]) % 4]);
      break;
    }
    default: {
      fuzz::Input in(data + 1, size - 1);
      check_association(in);
    }
  }
  return 0;
}
