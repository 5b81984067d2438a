// Tests of the SceneOptions key table: every key reads back what it was set to, sets its own field
// only, and rejects unknown keys and bad values with a reason naming the key and what it expects.
#include "dyncull/sim/scene_keys.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <clocale>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace {

using dyncull::Status;
using namespace dyncull::sim;

/// A value in range that differs from the default, as text (vectors: one value per component).
std::string other_value(const SceneKey& k, const std::string& current) {
  auto number = [&](double def) {
    double v = 0;
    if (std::isfinite(k.lo) && std::isfinite(k.hi)) v = k.lo + 0.37 * (k.hi - k.lo);
    else if (std::isfinite(k.lo)) v = k.lo + 1.25;
    else v = def + 1.5;
    if (k.type == SceneKeyType::Int) v = std::round(v) == def ? std::round(v) + 1 : std::round(v);
    if (v == def) v = std::isfinite(k.hi) ? k.hi : def + 2.5;
    return v;
  };
  switch (k.type) {
    case SceneKeyType::Int: return std::to_string(static_cast<long long>(number(std::stod(current))));
    case SceneKeyType::Double: return detail::format_number(number(std::stod(current)));
    case SceneKeyType::UInt64: return "18446744073709551615";  // the largest seed must survive the text
    case SceneKeyType::Bool: return current == "true" ? "false" : "true";
    case SceneKeyType::Vec2:
    case SceneKeyType::Vec3: {
      const int n = k.type == SceneKeyType::Vec2 ? 2 : 3;
      double c[3] = {};
      EXPECT_TRUE(detail::parse_components(current, n, c)) << k.name << " printed '" << current << "'";
      std::string s;
      for (int i = 0; i < n; ++i) s += (i ? ":" : "") + detail::format_number(number(c[i]) + 0.01 * i);
      return s;
    }
    case SceneKeyType::Enum: {
      EXPECT_GE(k.choices.size(), 2u) << k.name;
      return k.choices.front() == current ? k.choices.back() : k.choices.front();
    }
  }
  return current;
}

TEST(SceneKeys, NamesAreUniqueAndDocumented) {
  std::set<std::string> names;
  for (const SceneKey& k : scene_keys()) {
    EXPECT_TRUE(names.insert(k.name).second) << "duplicate key " << k.name;
    EXPECT_FALSE(k.help.empty()) << k.name;
    EXPECT_TRUE(k.set && k.get) << k.name;
    EXPECT_EQ(find_scene_key(k.name), &k);
  }
  EXPECT_EQ(find_scene_key("no_such_key"), nullptr);
  // The dotted names the command line documents.
  for (const char* name : {"actors.walking_speed_mps", "miss_rate", "trajectory.xyz_rotation_deg", "motion", "seed",
                           "depth_model.border_px", "trajectory.xyz_amplitude_m", "actors.loop_centre_m"})
    EXPECT_NE(find_scene_key(name), nullptr) << name;
}

// SceneOptions has 13 fields of its own, 8 in DepthNoiseOptions, 12 in TrajectoryOptions (besides the
// recorded samples, which are data), 15 in ActorOptions and 7 in DetectorModelOptions: a field added
// without a key fails here, so the table cannot silently fall behind.
TEST(SceneKeys, TableCoversEveryField) { EXPECT_EQ(scene_keys().size(), 13u + 8u + 12u + 15u + 7u); }

TEST(SceneKeys, EveryKeyRoundTripsItsDefaultAndAnotherValue) {
  for (const SceneKey& k : scene_keys()) {
    SceneOptions o;
    const std::string def = k.get(o);
    std::string reason;
    ASSERT_EQ(set_scene_key(&o, k.name, def, &reason), Status::Ok) << k.name << "=" << def << ": " << reason;
    EXPECT_EQ(k.get(o), def) << k.name;
    const std::string other = other_value(k, def);
    ASSERT_NE(other, def) << k.name;
    ASSERT_EQ(set_scene_key(&o, k.name, other, &reason), Status::Ok) << k.name << "=" << other << ": " << reason;
    EXPECT_EQ(k.get(o), other) << k.name;
  }
}

// Setting a key changes its own field and no other: no two accessors share a field.
TEST(SceneKeys, EachKeySetsOnlyItsOwnField) {
  const SceneOptions defaults;
  for (const SceneKey& k : scene_keys()) {
    SceneOptions o;
    ASSERT_EQ(set_scene_key(&o, k.name, other_value(k, k.get(o))), Status::Ok) << k.name;
    for (const SceneKey& other : scene_keys()) {
      if (&other == &k) EXPECT_NE(other.get(o), other.get(defaults)) << k.name << " did not change its field";
      else EXPECT_EQ(other.get(o), other.get(defaults)) << "setting " << k.name << " changed " << other.name;
    }
  }
}

TEST(SceneKeys, DoublesPrintShortAndExact) {
  EXPECT_EQ(detail::format_number(0.4), "0.4");
  EXPECT_EQ(detail::format_number(1341846313.0), "1341846313");
  const double third = 1.0 / 3.0;
  double back = 0;
  ASSERT_TRUE(detail::parse_double(detail::format_number(third), &back));
  EXPECT_EQ(back, third);
}

TEST(SceneKeys, AssignmentsApplyLeftToRightOverTheGivenOptions) {
  SceneOptions o;
  o.miss_rate = 0.3;  // a family's value stays unless a key overrides it
  std::string reason;
  ASSERT_EQ(apply_scene_assignments(&o, "actors.walking_speed_mps=0.9,,seed=7,trajectory.xyz_amplitude_m=0.1:0.2:0.3,"
                                        "motion=halfsphere,actors.sitting_person=off,seed=8",
                                    &reason),
            Status::Ok)
      << reason;
  EXPECT_DOUBLE_EQ(o.actors.walking_speed_mps, 0.9);
  EXPECT_EQ(o.seed, 8u);
  EXPECT_DOUBLE_EQ(o.trajectory.xyz_amplitude_m.y(), 0.2);
  EXPECT_EQ(o.motion, CameraMotion::Halfsphere);
  EXPECT_FALSE(o.actors.sitting_person);
  EXPECT_DOUBLE_EQ(o.miss_rate, 0.3);
  EXPECT_EQ(apply_scene_assignments(&o, "", &reason), Status::Ok);
}

TEST(SceneKeys, DifferenceIsTheAssignmentThatRebuildsTheOptions) {
  SceneOptions o;
  EXPECT_EQ(scene_difference(o), "");
  o.actors.loop_centre_m.x() = 0.25;
  o.false_positive_rate = 0.125;
  o.motion = CameraMotion::Static;
  const std::string diff = scene_difference(o);
  EXPECT_EQ(diff, "motion=static,false_positive_rate=0.125,actors.loop_centre_m=0.25:1.05");
  SceneOptions rebuilt;
  ASSERT_EQ(apply_scene_assignments(&rebuilt, diff), Status::Ok);
  EXPECT_EQ(scene_difference(rebuilt, o), "");
}

// A bad key or value: InvalidInput, the options untouched, and a reason naming the key and what it expects.
TEST(SceneKeys, BadKeysAndValuesAreRejectedWithTheExpectedTypeAndRange) {
  struct Case {
    const char* key;
    const char* value;
    const char* expected;  ///< part of the reason
  };
  const Case cases[] = {
      {"miss_rate", "1.5", "number [0, 1]"},
      {"miss_rate", "-0.1", "number [0, 1]"},
      {"miss_rate", "", "number [0, 1]"},
      {"miss_rate", "0.2x", "number [0, 1]"},
      {"miss_rate", " 0.2", "number [0, 1]"},
      {"fps", "0", "number [0.001, 1000]"},
      {"fps", "nan", "number [0.001, 1000]"},
      {"fps", "inf", "number [0.001, 1000]"},
      {"width", "1.5", "integer [1, 8192]"},
      {"width", "abc", "integer [1, 8192]"},
      {"width", "99999999999999999999", "integer [1, 8192]"},
      {"num_frames", "-1", "integer [0, 1000000]"},
      {"seed", "-1", "non-negative integer"},
      {"seed", "18446744073709551616", "non-negative integer"},
      {"actors.sitting_person", "maybe", "true or false"},
      {"actors.walking_people", "5", "integer [0, 4]"},
      {"actors.desk_people", "3", "integer [0, 2]"},
      {"detector.model", "yolo", "one of gaussian|calibrated"},
      {"trajectory.eye_m", "1:2", "x:y:z, each [-100, 100]"},
      {"trajectory.eye_m", "1:2:3:4", "x:y:z, each [-100, 100]"},
      {"trajectory.eye_m", "1:2:300", "x:y:z, each [-100, 100]"},
      {"actors.loop_semi_axes_m", "0.5", "x:y, each [0, 10]"},
      {"actors.texture_scale", "0", "number (0, 100]"},
      {"motion", "spiral", "one of static|xyz|rpy|halfsphere|recorded"},
  };
  for (const Case& c : cases) {
    SceneOptions o;
    std::string reason;
    EXPECT_EQ(set_scene_key(&o, c.key, c.value, &reason), Status::InvalidInput) << c.key << "=" << c.value;
    EXPECT_NE(reason.find(std::string("'") + c.key + "'"), std::string::npos) << reason;
    EXPECT_NE(reason.find(c.expected), std::string::npos) << reason;
    EXPECT_EQ(scene_difference(o), "") << c.key << "=" << c.value << " changed the options";
  }
  SceneOptions o;
  std::string reason;
  EXPECT_EQ(set_scene_key(&o, "actors.walking_speed", "1", &reason), Status::InvalidInput);
  EXPECT_NE(reason.find("unknown scene key 'actors.walking_speed'"), std::string::npos) << reason;
  EXPECT_EQ(apply_scene_assignments(&o, "seed=2,miss_rate", &reason), Status::InvalidInput);
  EXPECT_NE(reason.find("'miss_rate' is not key=value"), std::string::npos) << reason;
  EXPECT_EQ(apply_scene_assignments(&o, "seed=2,bogus=1", &reason), Status::InvalidInput);
  EXPECT_NE(reason.find("'bogus'"), std::string::npos) << reason;
  EXPECT_EQ(set_scene_key(nullptr, "seed", "1", &reason), Status::InvalidInput);
  EXPECT_EQ(apply_scene_assignments(nullptr, "seed=1", &reason), Status::InvalidInput);
}

// Unknown keys and items without '=' are user text: quoted by text::quote_token (escaped, cut at 32
// characters), so terminal escapes never reach the terminal, a NUL does not cut the reason and a
// 5,000-character key does not fill the screen.
TEST(SceneKeys, UnknownKeysAndItemsWithoutEqualsAreQuotedEscapedAndBounded) {
  SceneOptions o;
  std::string reason;
  EXPECT_EQ(apply_scene_assignments(&o, "\x1b[2Jbad=1", &reason), Status::InvalidInput);
  EXPECT_EQ(reason, "unknown scene key '\\x1b[2Jbad' (dynamic_vo --help lists the keys)");
  EXPECT_EQ(apply_scene_assignments(&o, std::string("ke\0y=1", 7), &reason), Status::InvalidInput);
  EXPECT_EQ(reason, "unknown scene key 'ke\\x00y' (dynamic_vo --help lists the keys)");
  EXPECT_EQ(apply_scene_assignments(&o, std::string(5000, 'k') + "=1", &reason), Status::InvalidInput);
  EXPECT_EQ(reason, "unknown scene key '" + std::string(32, 'k') + "'... (5000 bytes) (dynamic_vo --help lists the keys)");
  EXPECT_EQ(apply_scene_assignments(&o, "seed=1,\x07" "bell\n", &reason), Status::InvalidInput);
  EXPECT_EQ(reason, "scene assignment '\\x07bell\\x0a' is not key=value");
  EXPECT_EQ(apply_scene_assignments(&o, "seed=1," + std::string(5000, 'x'), &reason), Status::InvalidInput);
  EXPECT_LT(reason.size(), 100u) << reason.substr(0, 200);
}

// Frame i is stamped start_time_s + i / fps: a frame rate or a start time that makes the stamps
// infinite or equal is refused with the bound, not run with infinite stamps and Ok frames.
TEST(SceneKeys, FrameRateAndStartTimeKeepTheStampsFiniteAndDistinct) {
  SceneOptions o;
  std::string reason;
  EXPECT_EQ(apply_scene_assignments(&o, "fps=5e-324", &reason), Status::InvalidInput);
  EXPECT_EQ(reason, "scene key 'fps': expected number [0.001, 1000], got '5e-324' (frame rate, Hz; from 0.001 Hz the "
                    "frame stamps start_time_s + i / fps stay finite)");
  EXPECT_EQ(apply_scene_assignments(&o, "start_time_s=1e300", &reason), Status::InvalidInput);
  EXPECT_EQ(reason, "scene key 'start_time_s': expected number [-4000000000, 4000000000], got '1e300' (timestamp of "
                    "frame 0, s; within 4e9 s the stamps keep microseconds and stay distinct)");
  ASSERT_EQ(apply_scene_assignments(&o, "fps=0.001,start_time_s=4e9,num_frames=1000000", &reason), Status::Ok) << reason;
  const Scene slow(o);
  EXPECT_TRUE(std::isfinite(slow.timestamp(999999)));
  EXPECT_GT(slow.timestamp(999999), slow.timestamp(999998));
  ASSERT_EQ(apply_scene_assignments(&o, "fps=1000,start_time_s=-4e9", &reason), Status::Ok) << reason;
  const Scene fast(o);
  EXPECT_GT(fast.timestamp(999999) - fast.timestamp(999998), 0.9e-3);
}

// Numbers follow Python's grammar, as every number dyncull reads: float() for real keys, int() for
// integer keys (digits with single underscores, no fraction or exponent), in any C locale.
TEST(SceneKeys, NumbersFollowThePythonGrammarInAnyLocale) {
  const char* const previous = std::setlocale(LC_ALL, nullptr);
  const std::string saved = previous ? previous : "C";
  const bool comma_locale = std::setlocale(LC_ALL, "de_DE.UTF-8") != nullptr;
  SceneOptions o;
  std::string reason;
  EXPECT_EQ(set_scene_key(&o, "fps", "2_5", &reason), Status::Ok) << reason;
  EXPECT_EQ(o.fps, 25.0);
  EXPECT_EQ(set_scene_key(&o, "miss_rate", ".25", &reason), Status::Ok) << reason;
  EXPECT_EQ(o.miss_rate, 0.25);
  EXPECT_EQ(set_scene_key(&o, "width", "1_024", &reason), Status::Ok) << reason;
  EXPECT_EQ(o.width, 1024);
  EXPECT_EQ(set_scene_key(&o, "width", "+320", &reason), Status::Ok) << reason;
  EXPECT_EQ(o.width, 320);
  EXPECT_EQ(set_scene_key(&o, "seed", "18_446_744_073_709_551_615", &reason), Status::Ok) << reason;
  EXPECT_EQ(o.seed, 18446744073709551615ull);
  EXPECT_EQ(set_scene_key(&o, "trajectory.eye_m", "1_0:-2.5e0:.5", &reason), Status::Ok) << reason;
  EXPECT_EQ(o.trajectory.eye_m.x(), 10.0);
  const SceneOptions before = o;
  for (const auto& kv : std::vector<std::pair<const char*, const char*>>{{"miss_rate", "0,5"},
                                                                         {"fps", "2__5"},
                                                                         {"fps", "_25"},
                                                                         {"fps", "0x10"},
                                                                         {"width", "1e3"},
                                                                         {"width", "640.0"},
                                                                         {"width", "1_"},
                                                                         {"seed", "+-1"},
                                                                         {"seed", "1.0"}}) {
    EXPECT_EQ(set_scene_key(&o, kv.first, kv.second, &reason), Status::InvalidInput) << kv.first << "=" << kv.second;
  }
  EXPECT_EQ(scene_difference(o, before), "");
  // The value is quoted in the reason with control bytes escaped, and cut when long.
  EXPECT_EQ(set_scene_key(&o, "miss_rate", std::string("0.2\n", 4), &reason), Status::InvalidInput);
  EXPECT_NE(reason.find("'0.2\\x0a'"), std::string::npos) << reason;
  EXPECT_EQ(set_scene_key(&o, "miss_rate", std::string(5000, '1'), &reason), Status::InvalidInput);
  EXPECT_LT(reason.size(), 300u) << reason.size();
  std::setlocale(LC_ALL, saved.c_str());
  if (!comma_locale) GTEST_SKIP() << "de_DE.UTF-8 not installed: checked in the C locale only";
}

// After the keys, SceneOptions::validate() has the last word (here on options that were invalid before).
TEST(SceneKeys, AssignmentsEndWithTheSceneValidation) {
  SceneOptions o;
  o.fps = -1;
  std::string reason;
  EXPECT_EQ(apply_scene_assignments(&o, "seed=3", &reason), Status::InvalidInput);
  EXPECT_NE(reason.find("fps"), std::string::npos) << reason;
  EXPECT_EQ(apply_scene_assignments(&o, "fps=15", &reason), Status::Ok) << reason;
  // A recorded motion without a recording: the key is fine, the scene is not.
  EXPECT_EQ(apply_scene_assignments(&o, "motion=recorded", &reason), Status::InvalidInput);
  EXPECT_NE(reason.find("recorded"), std::string::npos) << reason;
}

TEST(SceneKeys, HelpListsEveryKeyWithItsDefault) {
  const std::string help = format_scene_keys();
  for (const SceneKey& k : scene_keys()) EXPECT_NE(help.find("  " + k.name + " "), std::string::npos) << k.name;
  EXPECT_NE(help.find("actors.walking_speed_mps"), std::string::npos);
  EXPECT_NE(help.find("(default 0.4)"), std::string::npos) << help;
}

TEST(SceneKeys, MotionsByName) {
  for (const CameraMotion m : camera_motions()) {
    CameraMotion back{};
    ASSERT_TRUE(camera_motion_from_string(to_string(m), &back)) << to_string(m);
    EXPECT_EQ(back, m);
  }
  CameraMotion m = CameraMotion::Xyz;
  EXPECT_TRUE(camera_motion_from_string("recorded", &m));
  EXPECT_EQ(m, CameraMotion::Recorded);
  const std::vector<CameraMotion> motions = camera_motions();
  EXPECT_EQ(std::count(motions.begin(), motions.end(), CameraMotion::Recorded), 0)
      << "camera_motions() lists the motions that need no data";
  m = CameraMotion::Xyz;
  EXPECT_FALSE(camera_motion_from_string("XYZ", &m));
  EXPECT_EQ(m, CameraMotion::Xyz);
}

}  // namespace
