/// @file motion_levels.hpp
/// Class id -> motion level table (RTD-SLAM, Gao et al. 2024, §III.B;
/// Zhang et al. 2023 Algorithm 1; DLD-SLAM, Yu et al. 2024, §3.4 sets D / H / S): high =
/// moves by itself, medium = easily moved, low = treated as static. Default: the full COCO-80 table.
///
/// API (used by box_rule.hpp, dynamic_probability.hpp and the pipeline):
///   MotionLevelTable t = MotionLevelTable::coco80();
///   t.level(class_id) -> MotionLevel;  t.set(id, level);  t.set("chair", MotionLevel::Low);
///   motion_level_score(level) -> S of DLD-SLAM eq. 3 (1 / 0.5 / 0).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace dyncull {

/// Ignore: the class takes no part in culling (unknown ids, or classes a user switched off). It is
/// distinct from Low, because a low-level box *protects* the features inside it (Zhu et al. 2024 Table 2).
enum class MotionLevel : std::uint8_t { Ignore = 0, Low = 1, Medium = 2, High = 3 };

constexpr const char* to_string(MotionLevel level) noexcept {
  switch (level) {
    case MotionLevel::Ignore: return "ignore";
    case MotionLevel::Low: return "low";
    case MotionLevel::Medium: return "medium";
    case MotionLevel::High: return "high";
  }
  return "unknown";
}

/// S of DLD-SLAM eq. 3 as Algorithm 1 defines it: 1 high, 0.5 medium, 0 low (the text's "1 for static"
/// contradicts Algorithm 1; Algorithm 1 is followed). Ignore scores 0 like Low.
template <class T = double>
constexpr T motion_level_score(MotionLevel level) noexcept {
  return level == MotionLevel::High ? T(1) : (level == MotionLevel::Medium ? T(0.5) : T(0));
}

/// COCO-80 class names in the detector's 0-based id order (YOLOv5/v8, Darknet coco.names).
inline const std::vector<std::string>& coco80_names() {
  static const std::vector<std::string> names = {
      "person",        "bicycle",      "car",           "motorcycle",    "airplane",     "bus",
      "train",         "truck",        "boat",          "traffic light", "fire hydrant", "stop sign",
      "parking meter", "bench",        "bird",          "cat",           "dog",          "horse",
      "sheep",         "cow",          "elephant",      "bear",          "zebra",        "giraffe",
      "backpack",      "umbrella",     "handbag",       "tie",           "suitcase",     "frisbee",
      "skis",          "snowboard",    "sports ball",   "kite",          "baseball bat", "baseball glove",
      "skateboard",    "surfboard",    "tennis racket", "bottle",        "wine glass",   "cup",
      "fork",          "knife",        "spoon",         "bowl",          "banana",       "apple",
      "sandwich",      "orange",       "broccoli",      "carrot",        "hot dog",      "pizza",
      "donut",         "cake",         "chair",         "couch",         "potted plant", "bed",
      "dining table",  "toilet",       "tv",            "laptop",        "mouse",        "remote",
      "keyboard",      "cell phone",   "microwave",     "oven",          "toaster",      "sink",
      "refrigerator",  "book",         "clock",         "vase",          "scissors",     "teddy bear",
      "hair drier",    "toothbrush"};
  return names;
}

/// Replaceable class -> level table. Ids outside the table map to Ignore.
class MotionLevelTable {
 public:
  MotionLevelTable() = default;
  /// A table of `names` with every class at `level`.
  explicit MotionLevelTable(std::vector<std::string> names, MotionLevel level = MotionLevel::Ignore)
      : names_(std::move(names)), levels_(names_.size(), level) {}

  /// Default COCO-80 levels.
  /// High: person and the ten animals (they move by themselves), and the self-propelled vehicles
  ///   (bicycle ... boat): every public dynamic-SLAM class list (DynaSLAM, YOLO_ORB_SLAM3,
  ///   Dynamic-VINS) treats them as dynamic. Parked-car scenes should set them to Medium.
  /// Medium: carried or pushed objects (bags, sports gear, tableware, food, chair, laptop, mouse,
  ///   remote, keyboard, phone, book, vase, scissors, teddy bear, hair drier, toothbrush).
  /// Low: furniture, appliances and street fixtures (traffic light ... bench, couch, potted plant,
  ///   bed, dining table, toilet, tv, microwave, oven, toaster, sink, refrigerator, clock).
  static MotionLevelTable coco80() {
    MotionLevelTable t(coco80_names(), MotionLevel::Medium);
    const int high[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23};
    const int low[] = {9, 10, 11, 12, 13, 57, 58, 59, 60, 61, 62, 68, 69, 70, 71, 72, 74};
    for (int id : high) t.levels_[static_cast<std::size_t>(id)] = MotionLevel::High;
    for (int id : low) t.levels_[static_cast<std::size_t>(id)] = MotionLevel::Low;
    return t;
  }

  std::size_t size() const { return levels_.size(); }

  MotionLevel level(int class_id) const {
    return (class_id >= 0 && static_cast<std::size_t>(class_id) < levels_.size())
               ? levels_[static_cast<std::size_t>(class_id)]
               : MotionLevel::Ignore;
  }

  /// Sets the level of an id; grows the table for ids past its end (new names are empty).
  /// Returns false for a negative id.
  bool set(int class_id, MotionLevel level) {
    if (class_id < 0) return false;
    const auto i = static_cast<std::size_t>(class_id);
    if (i >= levels_.size()) {
      levels_.resize(i + 1, MotionLevel::Ignore);
      names_.resize(i + 1);
    }
    levels_[i] = level;
    return true;
  }
  /// Sets the level of a named class; false when no class has that name.
  bool set(const std::string& name, MotionLevel level) {
    const int id = id_of(name);
    return id >= 0 && set(id, level);
  }

  /// Id of a class name, or -1.
  int id_of(const std::string& name) const {
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (names_[i] == name) return static_cast<int>(i);
    return -1;
  }
  /// Name of an id ("" when unknown).
  const std::string& name(int class_id) const {
    static const std::string empty;
    return (class_id >= 0 && static_cast<std::size_t>(class_id) < names_.size())
               ? names_[static_cast<std::size_t>(class_id)]
               : empty;
  }

 private:
  std::vector<std::string> names_;
  std::vector<MotionLevel> levels_;
};

}  // namespace dyncull
