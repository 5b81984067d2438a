/// @file scene_keys.hpp
/// Every field of sim::SceneOptions by its dotted name ("actors.walking_speed_mps", "miss_rate",
/// "trajectory.xyz_amplitude_m"), with its type, range, parser and printer, so that any scene can be
/// set from text (dynamic_vo --scene key=value,...) without recompiling. No paper equation.
#pragma once

#include "dyncull/core/status.hpp"
#include "dyncull/core/text.hpp"
#include "dyncull/core/types.hpp"
#include "dyncull/sim/scene.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <locale>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace dyncull::sim {

/// Value type of a scene key. Vectors are written with colons between components ("0:2.6" or
/// "0.3:0.15:0.25") so that a comma can separate assignments; enums by their to_string() names.
enum class SceneKeyType { Int, UInt64, Double, Bool, Vec2, Vec3, Enum };

constexpr const char* to_string(SceneKeyType type) noexcept {
  switch (type) {
    case SceneKeyType::Int: return "integer";
    case SceneKeyType::UInt64: return "non-negative integer";
    case SceneKeyType::Double: return "number";
    case SceneKeyType::Bool: return "true/false";
    case SceneKeyType::Vec2: return "x:y";
    case SceneKeyType::Vec3: return "x:y:z";
    case SceneKeyType::Enum: return "name";
  }
  return "unknown";
}

/// One settable field. `lo`/`hi` bound numbers and each vector component (`lo_open`: lo excluded);
/// they are wider than or equal to what SceneOptions::validate() accepts, which still runs after all
/// assignments (it knows relations between fields the key table does not).
struct SceneKey {
  std::string name;
  SceneKeyType type = SceneKeyType::Double;
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  std::string help;
  std::vector<std::string> choices;  ///< Enum: the accepted names
  /// Parses `value` into the field; false (with `reason` naming the key, the expected type and range)
  /// leaves the options unchanged.
  std::function<bool(SceneOptions&, const std::string&, std::string*)> set;
  /// The field's value as text that `set` reads back to the same value.
  std::function<std::string(const SceneOptions&)> get;

  /// "number (0, 1000]", "integer [0, 2]", "x:y:z, each [-100, 100]", "one of static|xyz|...".
  inline std::string expected() const;
};

/// The table, in SceneOptions declaration order (nested structs after the top-level fields). The recorded
/// trajectory's samples (trajectory.recorded_stamps_s, recorded_poses) are data, not keys: a caller loads
/// them from a file (dynamic_vo: a TUM sequence name as the motion).
inline const std::vector<SceneKey>& scene_keys();
/// The key named `name`, or nullptr.
inline const SceneKey* find_scene_key(const std::string& name);

/// Sets one key; InvalidInput with a reason naming the key (unknown, or the value's expected type and
/// range and what the key is) leaves `options` unchanged. User text in reasons (unknown keys, values,
/// items without '=') is quoted by text::quote_token: escaped and cut at 32 characters.
inline Status set_scene_key(SceneOptions* options, const std::string& key, const std::string& value,
                     std::string* reason = nullptr);
/// Applies "key=value[,key=value...]" left to right (a later key wins), then SceneOptions::validate().
/// On the first bad item or a failed validation returns InvalidInput with a reason; `options` then holds
/// the assignments before the bad item (the caller discards it).
inline Status apply_scene_assignments(SceneOptions* options, const std::string& assignments, std::string* reason = nullptr);
/// "key=value" for every key whose value differs from `reference`, comma separated: the text that
/// apply_scene_assignments() turns `reference` into `options` with.
inline std::string scene_difference(const SceneOptions& options, const SceneOptions& reference = SceneOptions{});
/// One line per key: "  name  type/range (default value)  help", for --help.
inline std::string format_scene_keys();

/// The camera motions that need no data (every one but Recorded), in enum order.
inline std::vector<CameraMotion> camera_motions();
/// Motion from its to_string() name (Recorded included); false for an unknown name.
inline bool camera_motion_from_string(const std::string& name, CameraMotion* motion);

// ---------------------------------------------------------------------------------------------
// Implementation
// ---------------------------------------------------------------------------------------------

namespace detail {

/// Shortest decimal text that reads back to exactly `v` (classic locale: '.' whatever the user's).
inline std::string format_number(double v) {
  for (int precision = 15; precision <= 17; ++precision) {
    std::ostringstream o;
    o.imbue(std::locale::classic());
    o.precision(precision);
    o << v;
    double r = 0;
    if ((text::parse_python_float(o.str(), &r) == text::NumberStatus::Ok && r == v) || precision == 17) return o.str();
  }
  return {};
}

/// A finite number as Python's float() reads it (core/text.hpp), in any locale.
inline bool parse_double(const std::string& token, double* out) {
  double v = 0;
  if (text::parse_python_float(token, &v) != text::NumberStatus::Ok || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

/// An integer as Python's int() reads it: the float() grammar restricted to a sign and digits with
/// single underscores (no fraction, exponent, inf or nan), read exactly into N by std::from_chars.
template <class N>
bool parse_integer(const std::string& token, N* out) {
  double ignored = 0;
  if (text::parse_python_float(token, &ignored) != text::NumberStatus::Ok) return false;  // grammar and length
  std::string digits;
  digits.reserve(token.size());
  for (std::size_t k = 0; k < token.size(); ++k) {
    const char c = token[k];
    if (c >= '0' && c <= '9') digits += c;
    else if (c == '-' && k == 0) digits += c;
    else if (!(c == '+' && k == 0) && c != '_') return false;
  }
  N v{};
  const std::from_chars_result r = std::from_chars(digits.data(), digits.data() + digits.size(), v);
  if (r.ec != std::errc() || r.ptr != digits.data() + digits.size()) return false;  // out of N's range
  *out = v;
  return true;
}

inline bool parse_bool(const std::string& text, bool* out) {
  if (text == "true" || text == "1" || text == "on" || text == "yes") *out = true;
  else if (text == "false" || text == "0" || text == "off" || text == "no") *out = false;
  else return false;
  return true;
}

/// Splits "a:b:c" into exactly n numbers.
inline bool parse_components(const std::string& text, int n, double* out) {
  std::size_t start = 0;
  for (int k = 0; k < n; ++k) {
    const std::size_t end = k + 1 < n ? text.find(':', start) : text.size();
    if (end == std::string::npos) return false;
    if (!parse_double(text.substr(start, end - start), &out[k])) return false;
    start = end + 1;
  }
  return true;
}

inline std::string format_range(double lo, double hi, bool lo_open) {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (!has_lo && !has_hi) return "finite";
  if (!has_hi) return std::string(lo_open ? "> " : ">= ") + format_number(lo);
  if (!has_lo) return "<= " + format_number(hi);
  return std::string(lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) + "]";
}

inline bool in_range(double v, const SceneKey& k) {
  return std::isfinite(v) && (k.lo_open ? v > k.lo : v >= k.lo) && v <= k.hi;
}

/// Field accessor: a captureless lambda returning a reference into the options.
template <class F>
using FieldRef = F& (*)(SceneOptions&);

/// Reads a field through its accessor without changing it (the accessor only forms a reference).
template <class F>
const F& read_field(FieldRef<F> ref, const SceneOptions& o) {
  return ref(const_cast<SceneOptions&>(o));
}

inline bool fail(const SceneKey& k, const std::string& value, std::string* reason) {
  if (reason)
    *reason = "scene key '" + k.name + "': expected " + k.expected() + ", got " + text::quote_token(value) + " (" +
              k.help + ")";
  return false;
}

inline SceneKey number_key(const char* name, FieldRef<double> ref, double lo, double hi, bool lo_open,
                           const char* help) {
  SceneKey k{name, SceneKeyType::Double, lo, hi, lo_open, help, {}, {}, {}};
  k.set = [k, ref](SceneOptions& o, const std::string& text, std::string* reason) {
    double v = 0;
    if (!parse_double(text, &v) || !in_range(v, k)) return fail(k, text, reason);
    ref(o) = v;
    return true;
  };
  k.get = [ref](const SceneOptions& o) { return format_number(read_field(ref, o)); };
  return k;
}

inline SceneKey int_key(const char* name, FieldRef<int> ref, int lo, int hi, const char* help) {
  SceneKey k{name, SceneKeyType::Int, static_cast<double>(lo), static_cast<double>(hi), false, help, {}, {}, {}};
  k.set = [k, ref](SceneOptions& o, const std::string& text, std::string* reason) {
    long long v = 0;
    if (!parse_integer(text, &v) || !in_range(static_cast<double>(v), k)) return fail(k, text, reason);
    ref(o) = static_cast<int>(v);
    return true;
  };
  k.get = [ref](const SceneOptions& o) { return std::to_string(read_field(ref, o)); };
  return k;
}

inline SceneKey uint64_key(const char* name, FieldRef<std::uint64_t> ref, const char* help) {
  SceneKey k{name, SceneKeyType::UInt64, 0, 18446744073709551615.0, false, help, {}, {}, {}};
  k.set = [k, ref](SceneOptions& o, const std::string& text, std::string* reason) {
    unsigned long long v = 0;
    if (!parse_integer(text, &v)) return fail(k, text, reason);  // unsigned: "-1" is refused, never 2^64 - 1
    ref(o) = static_cast<std::uint64_t>(v);
    return true;
  };
  k.get = [ref](const SceneOptions& o) { return std::to_string(read_field(ref, o)); };
  return k;
}

inline SceneKey bool_key(const char* name, FieldRef<bool> ref, const char* help) {
  SceneKey k{name, SceneKeyType::Bool, 0, 1, false, help, {}, {}, {}};
  k.set = [k, ref](SceneOptions& o, const std::string& text, std::string* reason) {
    bool v = false;
    if (!parse_bool(text, &v)) return fail(k, text, reason);
    ref(o) = v;
    return true;
  };
  k.get = [ref](const SceneOptions& o) { return std::string(read_field(ref, o) ? "true" : "false"); };
  return k;
}

template <int N>
SceneKey vector_key(const char* name, FieldRef<Eigen::Matrix<double, N, 1>> ref, double lo, double hi,
                    const char* help) {
  SceneKey k{name, N == 2 ? SceneKeyType::Vec2 : SceneKeyType::Vec3, lo, hi, false, help, {}, {}, {}};
  k.set = [k, ref](SceneOptions& o, const std::string& text, std::string* reason) {
    double c[N] = {};
    if (!parse_components(text, N, c)) return fail(k, text, reason);
    for (int i = 0; i < N; ++i)
      if (!in_range(c[i], k)) return fail(k, text, reason);
    for (int i = 0; i < N; ++i) ref(o)[i] = c[i];
    return true;
  };
  k.get = [ref](const SceneOptions& o) {
    std::string s;
    for (int i = 0; i < N; ++i) s += (i ? ":" : "") + format_number(read_field(ref, o)[i]);
    return s;
  };
  return k;
}

template <class E>
SceneKey enum_key(const char* name, FieldRef<E> ref, const std::vector<E>& values, const char* help) {
  SceneKey k{name, SceneKeyType::Enum, 0, 0, false, help, {}, {}, {}};
  for (const E v : values) k.choices.push_back(to_string(v));
  k.set = [k, ref, values](SceneOptions& o, const std::string& text, std::string* reason) {
    for (const E v : values) {
      if (text == to_string(v)) {
        ref(o) = v;
        return true;
      }
    }
    return fail(k, text, reason);
  };
  k.get = [ref](const SceneOptions& o) { return std::string(to_string(read_field(ref, o))); };
  return k;
}

/// The top-level keys: image, frames, camera motion, seed, detector rates, clipping.
inline void add_top_level_keys(std::vector<SceneKey>* keys) {
  std::vector<SceneKey>& k = *keys;
  using O = SceneOptions;
  constexpr double kMinFps = 1e-3;
  constexpr double kMaxStartTimeS = 4e9;
  k.push_back(int_key("width", [](O& o) -> int& { return o.width; }, 1, 8192, "image width, px"));
  k.push_back(int_key("height", [](O& o) -> int& { return o.height; }, 1, 8192, "image height, px"));
  // Frame i is stamped start_time_s + i / fps: at least 0.001 Hz keeps a million frames' stamps
  // finite and microseconds apart from the start time (5e-324 Hz would stamp every frame inf).
  k.push_back(number_key("fps", [](O& o) -> double& { return o.fps; }, kMinFps, 1000, false,
                         "frame rate, Hz; from 0.001 Hz the frame stamps start_time_s + i / fps stay finite"));
  k.push_back(int_key("num_frames", [](O& o) -> int& { return o.num_frames; }, 0, 1000000, "frames in the sequence"));
  k.push_back(enum_key<CameraMotion>("motion", [](O& o) -> CameraMotion& { return o.motion; },
                                     {CameraMotion::Static, CameraMotion::Xyz, CameraMotion::Rpy,
                                      CameraMotion::Halfsphere, CameraMotion::Recorded},
                                     "camera motion (recorded: needs a recorded trajectory)"));
  k.push_back(uint64_key("seed", [](O& o) -> std::uint64_t& { return o.seed; }, "textures, phases, noise, detections"));
  k.push_back(bool_key("depth_noise", [](O& o) -> bool& { return o.depth_noise; }, "Kinect-like depth noise and holes"));
  k.push_back(number_key("box_jitter_px", [](O& o) -> double& { return o.box_jitter_px; }, 0, 1000, false,
                         "std-dev of the jitter of each detection box edge, px"));
  k.push_back(number_key("miss_rate", [](O& o) -> double& { return o.miss_rate; }, 0, 1, false,
                         "probability that a visible instance gets no detection"));
  k.push_back(number_key("false_positive_rate", [](O& o) -> double& { return o.false_positive_rate; }, 0, 1, false,
                         "probability per frame of one spurious detection"));
  k.push_back(int_key("min_detection_pixels", [](O& o) -> int& { return o.min_detection_pixels; }, 0, 100000000,
                      "instances with fewer visible pixels are not detected"));
  // Within 4e9 s (TUM's are 1.3e9) a double resolves a microsecond (its spacing there is 4.8e-7 s), so
  // frames 1 ms apart (1000 Hz) keep distinct stamps; at 1e300 every frame would get the same stamp.
  k.push_back(number_key("start_time_s", [](O& o) -> double& { return o.start_time_s; }, -kMaxStartTimeS,
                         kMaxStartTimeS, false,
                         "timestamp of frame 0, s; within 4e9 s the stamps keep microseconds and stay distinct"));
  k.push_back(number_key("near_m", [](O& o) -> double& { return o.near_m; }, 0, 100, true,
                         "surfaces closer than this are clipped, m"));
}

/// The keys of depth_model: noise, quantisation, range and holes.
inline void add_depth_model_keys(std::vector<SceneKey>* keys) {
  std::vector<SceneKey>& k = *keys;
  using O = SceneOptions;
  k.push_back(number_key("depth_model.sigma_base_m", [](O& o) -> double& { return o.depth_model.sigma_base_m; }, 0, 1,
                         false, "depth sigma at the reference distance, m"));
  k.push_back(number_key("depth_model.sigma_quadratic", [](O& o) -> double& { return o.depth_model.sigma_quadratic; },
                         0, 1, false, "growth of the depth sigma with (z - reference)^2, 1/m"));
  k.push_back(number_key("depth_model.sigma_reference_m",
                         [](O& o) -> double& { return o.depth_model.sigma_reference_m; }, 0, 100, false,
                         "distance of minimal depth noise, m"));
  k.push_back(number_key("depth_model.units_per_metre", [](O& o) -> double& { return o.depth_model.units_per_metre; },
                         0, 1e9, true, "depth quantisation steps per metre"));
  k.push_back(number_key("depth_model.min_range_m", [](O& o) -> double& { return o.depth_model.min_range_m; }, 0, 100,
                         false, "closer surfaces give no depth, m"));
  k.push_back(number_key("depth_model.max_range_m", [](O& o) -> double& { return o.depth_model.max_range_m; }, 0, 1000,
                         true, "farther surfaces give no depth, m"));
  k.push_back(number_key("depth_model.edge_threshold_rel",
                         [](O& o) -> double& { return o.depth_model.edge_threshold_rel; }, 0, 10, false,
                         "relative depth step that makes holes"));
  k.push_back(int_key("depth_model.border_px", [](O& o) -> int& { return o.depth_model.border_px; }, 0, 8192,
                      "band along the image edges without depth, px"));
}

/// The keys of trajectory: each camera motion's rest pose and amplitudes.
inline void add_trajectory_keys(std::vector<SceneKey>* keys) {
  std::vector<SceneKey>& k = *keys;
  using O = SceneOptions;
  k.push_back(vector_key<3>("trajectory.eye_m", [](O& o) -> Vec3<double>& { return o.trajectory.eye_m; }, -100, 100,
                            "rest position of the camera centre (world, z up), m"));
  k.push_back(vector_key<3>("trajectory.target_m", [](O& o) -> Vec3<double>& { return o.trajectory.target_m; }, -100,
                            100, "point the rest pose looks at, m"));
  k.push_back(number_key("trajectory.static_jitter_m", [](O& o) -> double& { return o.trajectory.static_jitter_m; }, 0,
                         1, false, "static: translation amplitude per axis, m"));
  k.push_back(number_key("trajectory.static_jitter_deg", [](O& o) -> double& { return o.trajectory.static_jitter_deg; },
                         0, 90, false, "static: rotation amplitude per axis, deg"));
  k.push_back(vector_key<3>("trajectory.xyz_amplitude_m",
                            [](O& o) -> Vec3<double>& { return o.trajectory.xyz_amplitude_m; }, 0, 5,
                            "xyz: amplitude right:down:forward, m"));
  k.push_back(number_key("trajectory.xyz_rotation_deg", [](O& o) -> double& { return o.trajectory.xyz_rotation_deg; },
                         0, 90, false, "xyz: hand-held rotation amplitude, deg"));
  k.push_back(vector_key<3>("trajectory.rpy_amplitude_deg",
                            [](O& o) -> Vec3<double>& { return o.trajectory.rpy_amplitude_deg; }, 0, 180,
                            "rpy: amplitude yaw:pitch:roll, deg"));
  k.push_back(number_key("trajectory.rpy_translation_m", [](O& o) -> double& { return o.trajectory.rpy_translation_m; },
                         0, 1, false, "rpy: translation amplitude, m"));
  k.push_back(number_key("trajectory.halfsphere_radius_m",
                         [](O& o) -> double& { return o.trajectory.halfsphere_radius_m; }, 0, 5, false,
                         "halfsphere: radius, m"));
  k.push_back(number_key("trajectory.halfsphere_azimuth_deg",
                         [](O& o) -> double& { return o.trajectory.halfsphere_azimuth_deg; }, 0, 89, false,
                         "halfsphere: azimuth swing, deg (under 90 keeps one hemisphere)"));
  k.push_back(number_key("trajectory.halfsphere_elevation_deg",
                         [](O& o) -> double& { return o.trajectory.halfsphere_elevation_deg; }, 0, 89, false,
                         "halfsphere: elevation swing, deg"));
  k.push_back(number_key("trajectory.recorded_start_s", [](O& o) -> double& { return o.trajectory.recorded_start_s; },
                         0, 1e6, false, "recorded: seconds into the recording where frame 0 starts"));
}

/// The keys of actors: walkers, seated people, the pushed chair, textures.
inline void add_actor_keys(std::vector<SceneKey>* keys) {
  std::vector<SceneKey>& k = *keys;
  using O = SceneOptions;
  k.push_back(int_key("actors.walking_people", [](O& o) -> int& { return o.actors.walking_people; }, 0, 4,
                      "people walking the elliptic loop"));
  k.push_back(bool_key("actors.sitting_person", [](O& o) -> bool& { return o.actors.sitting_person; },
                       "a person on a chair moving head, torso and arms"));
  k.push_back(bool_key("actors.pushed_chair", [](O& o) -> bool& { return o.actors.pushed_chair; },
                       "a chair pushed once"));
  k.push_back(number_key("actors.walking_speed_mps", [](O& o) -> double& { return o.actors.walking_speed_mps; }, 0, 5,
                         false, "mean walking speed along the loop, m/s"));
  k.push_back(vector_key<2>("actors.loop_centre_m", [](O& o) -> Vec2<double>& { return o.actors.loop_centre_m; }, -10,
                            10, "centre of the walking loop on the floor (world x:y), m"));
  k.push_back(vector_key<2>("actors.loop_semi_axes_m", [](O& o) -> Vec2<double>& { return o.actors.loop_semi_axes_m; },
                            0, 10, "semi-axes of the walking loop (x:y), m"));
  k.push_back(number_key("actors.walker_start_phase_rad",
                         [](O& o) -> double& { return o.actors.walker_start_phase_rad; }, -100, 100, false,
                         "first walker's loop phase at t = 0, rad"));
  k.push_back(number_key("actors.walker_gap_rad", [](O& o) -> double& { return o.actors.walker_gap_rad; }, -100, 100,
                         false, "phase of each walker behind the one before, rad"));
  k.push_back(number_key("actors.push_start_s", [](O& o) -> double& { return o.actors.push_start_s; }, -1e6, 1e6,
                         false, "the chair starts moving, s"));
  k.push_back(number_key("actors.push_end_s", [](O& o) -> double& { return o.actors.push_end_s; }, -1e6, 1e6, false,
                         "the chair stops moving, s"));
  k.push_back(number_key("actors.wall_contrast", [](O& o) -> double& { return o.actors.wall_contrast; }, 0, 1, false,
                         "texture contrast of walls, floor and ceiling"));
  k.push_back(number_key("actors.texture_scale", [](O& o) -> double& { return o.actors.texture_scale; }, 0, 100, true,
                         "multiplies every texture cell size (larger = fewer corners)"));
  k.push_back(int_key("actors.desk_people", [](O& o) -> int& { return o.actors.desk_people; }, 0, 2,
                      "people seated at the desk in front of the camera (as in fr3/sitting_*)"));
  k.push_back(number_key("actors.desk_motion_scale", [](O& o) -> double& { return o.actors.desk_motion_scale; }, 0, 10,
                         false, "scales the desk people's sway, head turns, gestures and swivels"));
  k.push_back(bool_key("actors.desk_clutter", [](O& o) -> bool& { return o.actors.desk_clutter; },
                       "monitors, keyboards, mice, bottle, cup, book and laptop on the desk"));
}

/// The keys of detector: the noise model and its calibrated parameters.
inline void add_detector_keys(std::vector<SceneKey>* keys) {
  std::vector<SceneKey>& k = *keys;
  using O = SceneOptions;
  k.push_back(enum_key<DetectorModel>("detector.model", [](O& o) -> DetectorModel& { return o.detector.model; },
                                      {DetectorModel::Gaussian, DetectorModel::Calibrated},
                                      "detector noise model (calibrated: as YOLOv8n on TUM fr3)"));
  k.push_back(number_key("detector.tail_probability", [](O& o) -> double& { return o.detector.tail_probability; }, 0,
                         1, false, "calibrated: probability of a heavy-tailed box edge jump"));
  k.push_back(number_key("detector.tail_scale", [](O& o) -> double& { return o.detector.tail_scale; }, 0, 1000, false,
                         "calibrated: scale of the jumps, in box_jitter_px"));
  k.push_back(number_key("detector.object_miss_rate", [](O& o) -> double& { return o.detector.object_miss_rate; }, 0,
                         1, false, "calibrated: extra miss probability of objects other than people and monitors"));
  k.push_back(number_key("detector.confidence_sd", [](O& o) -> double& { return o.detector.confidence_sd; }, 0, 1,
                         false, "calibrated: spread of a detection's confidence"));
  k.push_back(number_key("detector.border_confidence_drop",
                         [](O& o) -> double& { return o.detector.border_confidence_drop; }, 0, 1, false,
                         "calibrated: confidence lost by a box cut by the image border"));
  k.push_back(number_key("detector.min_confidence", [](O& o) -> double& { return o.detector.min_confidence; }, 0, 1,
                         false, "calibrated: detections below it are dropped"));
}

inline std::vector<SceneKey> make_scene_keys() {
  std::vector<SceneKey> k;
  add_top_level_keys(&k);
  add_depth_model_keys(&k);
  add_trajectory_keys(&k);
  add_actor_keys(&k);
  add_detector_keys(&k);
  return k;
}

}  // namespace detail

inline std::string SceneKey::expected() const {
  switch (type) {
    case SceneKeyType::Int:
    case SceneKeyType::Double: return std::string(to_string(type)) + " " + detail::format_range(lo, hi, lo_open);
    case SceneKeyType::UInt64: return to_string(type);
    case SceneKeyType::Bool: return "true or false";
    case SceneKeyType::Vec2:
    case SceneKeyType::Vec3:
      return std::string(to_string(type)) + ", each " + detail::format_range(lo, hi, lo_open);
    case SceneKeyType::Enum: {
      std::string names;
      for (const std::string& c : choices) names += (names.empty() ? "" : "|") + c;
      return "one of " + names;
    }
  }
  return "?";
}

inline const std::vector<SceneKey>& scene_keys() {
  static const std::vector<SceneKey> keys = detail::make_scene_keys();
  return keys;
}

inline const SceneKey* find_scene_key(const std::string& name) {
  for (const SceneKey& k : scene_keys())
    if (k.name == name) return &k;
  return nullptr;
}

inline Status set_scene_key(SceneOptions* options, const std::string& key, const std::string& value,
                            std::string* reason) {
  if (options == nullptr) {
    if (reason) *reason = "no options to set";
    return Status::InvalidInput;
  }
  const SceneKey* k = find_scene_key(key);
  if (k == nullptr) {
    if (reason) *reason = "unknown scene key " + text::quote_token(key) + " (dynamic_vo --help lists the keys)";
    return Status::InvalidInput;
  }
  if (!k->set(*options, value, reason)) return Status::InvalidInput;
  if (reason) reason->clear();
  return Status::Ok;
}

inline Status apply_scene_assignments(SceneOptions* options, const std::string& assignments, std::string* reason) {
  if (options == nullptr) {
    if (reason) *reason = "no options to set";
    return Status::InvalidInput;
  }
  std::size_t start = 0;
  while (start <= assignments.size()) {
    std::size_t end = assignments.find(',', start);
    if (end == std::string::npos) end = assignments.size();
    const std::string item = assignments.substr(start, end - start);
    start = end + 1;
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) {
      if (reason) *reason = "scene assignment " + text::quote_token(item) + " is not key=value";
      return Status::InvalidInput;
    }
    const Status s = set_scene_key(options, item.substr(0, eq), item.substr(eq + 1), reason);
    if (s != Status::Ok) return s;
  }
  std::string why;
  if (options->validate(&why) != Status::Ok) {
    if (reason) *reason = "scene options invalid: " + why;
    return Status::InvalidInput;
  }
  if (reason) reason->clear();
  return Status::Ok;
}

inline std::string scene_difference(const SceneOptions& options, const SceneOptions& reference) {
  std::string out;
  for (const SceneKey& k : scene_keys()) {
    const std::string v = k.get(options);
    if (v != k.get(reference)) out += (out.empty() ? "" : ",") + k.name + "=" + v;
  }
  return out;
}

inline std::string format_scene_keys() {
  const SceneOptions defaults;
  std::size_t width = 0;
  for (const SceneKey& k : scene_keys()) width = std::max(width, k.name.size());
  std::string out;
  for (const SceneKey& k : scene_keys()) {
    out += "  " + k.name + std::string(width + 2 - k.name.size(), ' ') + k.expected() + " (default " +
           k.get(defaults) + "): " + k.help + "\n";
  }
  return out;
}

inline std::vector<CameraMotion> camera_motions() {
  return {CameraMotion::Static, CameraMotion::Xyz, CameraMotion::Rpy, CameraMotion::Halfsphere};
}

inline bool camera_motion_from_string(const std::string& name, CameraMotion* motion) {
  std::vector<CameraMotion> all = camera_motions();
  all.push_back(CameraMotion::Recorded);
  for (const CameraMotion m : all) {
    if (name == to_string(m)) {
      if (motion) *motion = m;
      return true;
    }
  }
  return false;
}

}  // namespace dyncull::sim
