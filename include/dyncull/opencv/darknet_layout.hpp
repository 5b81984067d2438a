/// @file darknet_layout.hpp
/// What a Darknet cfg says its weights file and outputs must be, read from the cfg text alone: the
/// channels through every layer, the float count of every convolution (biases, batch-norm scales, means
/// and variances, kernels), hence the weights file's exact size, and the [yolo] heads (their count,
/// classes and anchors per cell, each fed by a convolution of anchors x (5 + classes) filters). A
/// truncated, padded or foreign weights file, or a head that does not fit, is refused before OpenCV reads
/// it (Redmon & Farhadi 2018 for the layers; the weights layout as Darknet's load_weights writes it). No
/// OpenCV needed; standard library only.
///
/// API:
///   DarknetLayout layout;  std::string why;
///   if (!darknet_layout(cfg_text, &layout, &why)) ...             // "layer 12 [route]: layers=-40 ..."
///   layout.weights_bytes(major, minor)                              // header + 4 x floats
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace dyncull {
namespace cv_adapter {

/// A Darknet network's sizes as its cfg gives them.
struct DarknetLayout {
  std::uint64_t num_floats = 0;  ///< float32 values the weights file holds after its header
  struct Head {
    int layer = 0;    ///< index of the [yolo] section (0 = the first section after [net])
    int classes = 0;  ///< classes=
    int anchors = 0;  ///< entries of mask= (anchors per grid cell)
  };
  std::vector<Head> heads;  ///< [yolo] layers in cfg order (OpenCV's outputs, one per head); may be empty
  int input_width = 0;      ///< [net] width= and height=: the input the network was trained at (0: not given)
  int input_height = 0;

  /// Bytes of a weights file of this layout: the header (major, minor, revision as int32, then "seen"
  /// as int64 from version 0.2 on, else int32) and the floats.
  std::uint64_t weights_bytes(std::int32_t major, std::int32_t minor) const {
    const std::uint64_t header = (major * 10 + minor >= 2) ? 20 : 16;
    return header + 4 * num_floats;
  }
};

namespace detail {

struct CfgSection {
  std::string type;
  std::vector<std::pair<std::string, std::string>> keys;
  const std::string* find(const char* key) const {
    for (const auto& kv : keys)
      if (kv.first == key) return &kv.second;
    return nullptr;
  }
};

inline std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

/// Sections of a cfg: "[type]" lines, "key=value" lines, '#' and ';' comments.
inline bool cfg_sections(std::string_view text, std::vector<CfgSection>* out, std::string* why) {
  std::size_t line_no = 0;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
    ++line_no;
    line = trimmed(line.substr(0, line.find_first_of("#;")));
    if (line.empty()) continue;
    if (line.front() == '[') {
      if (line.back() != ']') return (*why = "cfg line " + std::to_string(line_no) + ": a section without ']'", false);
      out->push_back(CfgSection{std::string(trimmed(line.substr(1, line.size() - 2))), {}});
      continue;
    }
    const std::size_t eq = line.find('=');
    if (eq == std::string_view::npos || out->empty())
      return (*why = "cfg line " + std::to_string(line_no) + ": expected [section] or key=value", false);
    out->back().keys.emplace_back(std::string(trimmed(line.substr(0, eq))), std::string(trimmed(line.substr(eq + 1))));
  }
  return true;
}

/// Integers of a comma-separated list ("-1,-3, -5"); false on anything else or more than `max` values.
inline bool cfg_ints(const std::string& value, std::vector<long>* out, std::size_t max = 4096) {
  out->clear();
  std::string_view rest(value);
  while (true) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = trimmed(rest.substr(0, comma));
    long v = 0;
    const auto res = std::from_chars(item.data(), item.data() + item.size(), v);
    if (item.empty() || res.ec != std::errc() || res.ptr != item.data() + item.size() || out->size() >= max) return false;
    out->push_back(v);
    if (comma == std::string_view::npos) return true;
    rest.remove_prefix(comma + 1);
  }
}

/// key's integer in [lo, hi], or `fallback` when absent; false when present and not such an integer.
inline bool cfg_int(const CfgSection& s, const char* key, long fallback, long lo, long hi, long* out) {
  const std::string* v = s.find(key);
  if (!v) return (*out = fallback, true);
  std::vector<long> one;
  if (!cfg_ints(*v, &one, 1) || one.size() != 1 || one[0] < lo || one[0] > hi) return false;
  *out = one[0];
  return true;
}

}  // namespace detail

/// Reads `cfg` (a Darknet .cfg's text) into `*layout`; false with `*why` naming the layer and key for
/// a cfg whose sizes cannot be followed: a missing [net], a layer type without a known channel rule, a
/// route to a layer that does not exist, a key out of range, a [yolo] not fed by a convolution of
/// anchors x (5 + classes) filters. Layer types: convolutional, maxpool, avgpool, dropout, upsample,
/// shortcut, route (with groups / group_id), reorg, yolo, region.
inline bool darknet_layout(std::string_view cfg, DarknetLayout* layout, std::string* why) {
  *layout = DarknetLayout{};
  std::vector<detail::CfgSection> sections;
  if (!detail::cfg_sections(cfg, &sections, why)) return false;
  if (sections.empty() || (sections[0].type != "net" && sections[0].type != "network"))
    return (*why = "cfg: the first section is not [net]", false);
  long channels = 0, width = 0, height = 0;
  if (!detail::cfg_int(sections[0], "channels", 3, 1, 4096, &channels))
    return (*why = "cfg [net]: channels must be in [1, 4096]", false);
  if (!detail::cfg_int(sections[0], "width", 0, 0, 4096, &width) ||
      !detail::cfg_int(sections[0], "height", 0, 0, 4096, &height))
    return (*why = "cfg [net]: width and height must be in [0, 4096]", false);
  layout->input_width = static_cast<int>(width);
  layout->input_height = static_cast<int>(height);
  constexpr long kMaxFilters = 1 << 16;
  std::vector<long> out;       // output channels per layer
  std::vector<long> filters;   // filters of a convolution, 0 for other layers
  for (std::size_t k = 1; k < sections.size(); ++k) {
    const detail::CfgSection& s = sections[k];
    const int index = static_cast<int>(k - 1);
    const std::string where = "cfg layer " + std::to_string(index) + " [" + s.type + "]: ";
    const long in = out.empty() ? channels : out.back();
    long c = in, n = 0;
    if (s.type == "convolutional") {
      long size = 0, groups = 0, bn = 0;
      if (!detail::cfg_int(s, "filters", 1, 1, kMaxFilters, &n)) return (*why = where + "filters must be in [1, 65536]", false);
      if (!detail::cfg_int(s, "size", 1, 1, 64, &size)) return (*why = where + "size must be in [1, 64]", false);
      if (!detail::cfg_int(s, "groups", 1, 1, kMaxFilters, &groups) || in % groups != 0)
        return (*why = where + "groups must divide the " + std::to_string(in) + " input channels", false);
      if (!detail::cfg_int(s, "batch_normalize", 0, 0, 1, &bn)) return (*why = where + "batch_normalize must be 0 or 1", false);
      layout->num_floats += static_cast<std::uint64_t>(n) * (bn ? 4u : 1u) +
                            static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(in / groups) *
                                static_cast<std::uint64_t>(size * size);
      c = n;
    } else if (s.type == "route") {
      std::vector<long> layers;
      const std::string* v = s.find("layers");
      if (!v || !detail::cfg_ints(*v, &layers, 64) || layers.empty())
        return (*why = where + "layers must list 1 to 64 layer indices", false);
      c = 0;
      for (long l : layers) {
        const long at = l < 0 ? index + l : l;
        if (at < 0 || at >= index) return (*why = where + "layers names layer " + std::to_string(l) + ", which is not before it", false);
        c += out[static_cast<std::size_t>(at)];
      }
      long groups = 1, group_id = 0;
      if (!detail::cfg_int(s, "groups", 1, 1, kMaxFilters, &groups) || c % groups != 0 ||
          !detail::cfg_int(s, "group_id", 0, 0, groups - 1, &group_id))
        return (*why = where + "groups must divide the routed channels, group_id below groups", false);
      c /= groups;
    } else if (s.type == "reorg") {
      long stride = 2;
      if (!detail::cfg_int(s, "stride", 2, 1, 16, &stride)) return (*why = where + "stride must be in [1, 16]", false);
      c = in * stride * stride;
    } else if (s.type == "yolo") {
      long classes = 0;
      std::vector<long> mask;
      const std::string* m = s.find("mask");
      if (!detail::cfg_int(s, "classes", 20, 1, 100000, &classes)) return (*why = where + "classes must be in [1, 100000]", false);
      if (!m || !detail::cfg_ints(*m, &mask, 64) || mask.empty()) return (*why = where + "mask must list 1 to 64 anchors", false);
      const long need = static_cast<long>(mask.size()) * (5 + classes);
      if (filters.empty() || filters.back() != need)
        return (*why = where + "is fed by " +
                       (filters.empty() || filters.back() == 0 ? std::string("no convolution")
                                                               : std::to_string(filters.back()) + " filters") +
                       ", its " + std::to_string(mask.size()) + " anchors of " + std::to_string(classes) +
                       " classes need a convolution of " + std::to_string(need),
                false);
      layout->heads.push_back(DarknetLayout::Head{index, static_cast<int>(classes), static_cast<int>(mask.size())});
    } else if (s.type != "maxpool" && s.type != "avgpool" && s.type != "dropout" && s.type != "upsample" &&
               s.type != "shortcut" && s.type != "region") {
      return (*why = where + "a layer type whose weights cannot be counted here", false);
    }
    out.push_back(c);
    filters.push_back(n);
  }
  return true;  // a cfg without [yolo] layers is the caller's to report (its outputs are no YOLO head)
}

}  // namespace cv_adapter
}  // namespace dyncull
