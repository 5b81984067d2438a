// Pins the per-feature labels and reasons of every preset on short synthetic sequences (state carried
// frame to frame: box tracker, last sub-box votes, static history, keyframes) to recorded hashes, so that a
// restructuring of the pipeline that is meant to keep its behaviour is checked feature by feature.
// A deliberate change of behaviour updates the hashes in the same commit, saying why.
#include "dyncull/culling/pipeline.hpp"
#include "dyncull/culling/presets.hpp"

#include "support/culling_frames.hpp"
#include "support/culling_scenes.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace dyncull {
namespace {

using test::SceneConfig;

/// FNV-1a over bytes.
struct Hash {
  std::uint64_t h = 1469598103934665603ull;
  void add(std::uint64_t v) {
    for (int b = 0; b < 8; ++b) {
      h ^= (v >> (8 * b)) & 0xFF;
      h *= 1099511628211ull;
    }
  }
};

template <class T>
struct NamedOptions {
  const char* name;
  PipelineOptions<T> options;
};

/// The papers' presets, the recommended one, and variants of it that switch on its remaining stages.
template <class T>
std::vector<NamedOptions<T>> golden_presets() {
  std::vector<NamedOptions<T>> out = {
      {"none", presets::none<T>()},           {"dld_slam", presets::dld_slam<T>()},
      {"rtd_slam", presets::rtd_slam<T>()},   {"zhu_2024", presets::zhu_2024<T>()},
      {"dfd_slam", presets::dfd_slam<T>()},   {"zhang_2023", presets::zhang_2023<T>()},
      {"recommended", presets::recommended<T>()}};
  PipelineOptions<T> o = presets::recommended<T>();
  o.multiview.enabled = true;
  out.push_back({"recommended+multiview", o});
  o = presets::recommended<T>();
  o.probability.enabled = true;
  o.subbox.verifies_candidates = true;
  out.push_back({"recommended+probability", o});
  o = presets::dld_slam<T>();
  o.probability.flow_model = FlowModel::Fundamental;
  o.moving_consistency.enabled = true;
  o.tracker.enabled = true;
  out.push_back({"dld_slam+fundamental+tracker", o});
  return out;
}

/// Frame k of a sequence: the scene drawn with seed k, tracks over 1-3 frames, the first box missed in
/// frame 3 (the tracker carries it), a keyframe every third frame.
template <class T>
struct GoldenFrame {
  test::CullingScene<T> scene;
  std::vector<Detection<T>> detections;
  std::vector<std::int64_t> ids;
  int evidence_frames = 0;
  bool keyframe = false;
};

template <class T>
std::vector<GoldenFrame<T>> golden_sequence(SceneConfig config, int frames) {
  std::vector<GoldenFrame<T>> out;
  for (int k = 0; k < frames; ++k) {
    config.seed = 100 + static_cast<std::uint64_t>(k);
    config.frames_between = 1 + k % 3;
    GoldenFrame<T> f;
    f.scene = test::make_culling_scene<T>(config);
    for (std::size_t b = 0; b < f.scene.detections.size(); ++b) {
      if (k == 3 && b == 0) continue;
      const auto& d = f.scene.detections[b];
      f.detections.push_back(Detection<T>{d.box.template cast<T>(), d.class_id, T(d.confidence)});
    }
    f.ids.resize(f.scene.size());
    for (std::size_t i = 0; i < f.ids.size(); ++i) f.ids[i] = static_cast<std::int64_t>(i);
    f.evidence_frames = k % 4;
    f.keyframe = k % 3 == 0;
    out.push_back(std::move(f));
  }
  return out;
}

template <class T>
std::uint64_t hash_run(const std::vector<GoldenFrame<T>>& seq, const SceneConfig& config,
                       const PipelineOptions<T>& options) {
  PipelineState<T> state;
  const auto kf = test::make_scene_keyframe<T>(config, 8, 600);
  state.keyframes.push(kf.cam_from_world, kf.keypoints, kf.depth_m);
  Hash h;
  for (const GoldenFrame<T>& g : seq) {
    auto frame = test::frame_of(g.scene, g.detections);
    frame.track_ids = &g.ids;
    frame.points_3d = &g.scene.prev_points_world;
    frame.is_keyframe = g.keyframe;
    frame.evidence_frames = g.evidence_frames;
    const PipelineResult<T>& r = cull_frame(frame, options, &state);
    h.add(static_cast<std::uint64_t>(r.status));
    h.add(r.labels.size());
    for (std::size_t i = 0; i < r.labels.size(); ++i) {
      h.add(static_cast<std::uint64_t>(r.labels[i]));
      h.add(static_cast<std::uint64_t>(r.reasons[i]));
    }
    h.add(r.num_static);
    h.add(static_cast<std::uint64_t>(r.guard));
  }
  return h.h;
}

struct Golden {
  const char* sequence;
  const char* preset;
  int scalar_bytes;  ///< 4: float, 8: double
  std::uint64_t hash;
};

// The hashes hold for g++ on x86-64; clang draws the synthetic scenes' floating point slightly differently,
// so under clang (the sanitizer build) the sequences run through every preset without the comparison.
#if defined(__GNUC__) && !defined(__clang__)
constexpr bool kCompareHashes = true;
#else
constexpr bool kCompareHashes = false;
#endif

// Recorded from the pipeline; see the file comment.
const Golden kGolden[] = {
    {"walking", "none", 4, 0xdb6cfcccd251d5bbull},
    {"walking", "dld_slam", 4, 0xb27f6c41a43af634ull},
    {"walking", "rtd_slam", 4, 0x6d64cc2f0c3db000ull},
    {"walking", "zhu_2024", 4, 0x092ca26bbca118faull},
    {"walking", "dfd_slam", 4, 0xf602bd46ab433621ull},
    {"walking", "zhang_2023", 4, 0x58d80cb62d9d3f70ull},
    {"walking", "recommended", 4, 0x3e9f4f1fc0222375ull},
    {"walking", "recommended+multiview", 4, 0xffcbbfdefb8ede0dull},
    {"walking", "recommended+probability", 4, 0x0cb5ef9b04788480ull},
    {"walking", "dld_slam+fundamental+tracker", 4, 0x27e67c45ead4d37dull},
    {"seated", "none", 4, 0x69dc837b4cc728afull},
    {"seated", "dld_slam", 4, 0xf9f057552b93da8dull},
    {"seated", "rtd_slam", 4, 0x1be0a99db4a2a010ull},
    {"seated", "zhu_2024", 4, 0x70defefbdfbb7445ull},
    {"seated", "dfd_slam", 4, 0x56351946f0f66bfaull},
    {"seated", "zhang_2023", 4, 0xd3f4d06f8a44e25full},
    {"seated", "recommended", 4, 0xe43e51720f58a59bull},
    {"seated", "recommended+multiview", 4, 0xc4b7b2b08342fdd8ull},
    {"seated", "recommended+probability", 4, 0xbc4aa8e80091586cull},
    {"seated", "dld_slam+fundamental+tracker", 4, 0xaa062c671a913284ull},
    {"slow", "none", 4, 0xdb6cfcccd251d5bbull},
    {"slow", "dld_slam", 4, 0x5cdb057f7568ab2dull},
    {"slow", "rtd_slam", 4, 0x96c79b0f603c0d94ull},
    {"slow", "zhu_2024", 4, 0x092ca26bbca118faull},
    {"slow", "dfd_slam", 4, 0x123e71375096d5abull},
    {"slow", "zhang_2023", 4, 0x58d80cb62d9d3f70ull},
    {"slow", "recommended", 4, 0x1645b1afaf9865c2ull},
    {"slow", "recommended+multiview", 4, 0x5113f578f35fce42ull},
    {"slow", "recommended+probability", 4, 0x0b5641bbc2a3814cull},
    {"slow", "dld_slam+fundamental+tracker", 4, 0x75fe4de4efa8dd30ull},
    {"all_dynamic", "none", 4, 0x1670cfe1e06684bbull},
    {"all_dynamic", "dld_slam", 4, 0xa116d65eb6b05e0full},
    {"all_dynamic", "rtd_slam", 4, 0x0f53a341d0f1f5b9ull},
    {"all_dynamic", "zhu_2024", 4, 0x0f53a341d0f1f5b9ull},
    {"all_dynamic", "dfd_slam", 4, 0x1670cfe1e06684bbull},
    {"all_dynamic", "zhang_2023", 4, 0x0f53a341d0f1f5b9ull},
    {"all_dynamic", "recommended", 4, 0x2eb6b978c8793a8bull},
    {"all_dynamic", "recommended+multiview", 4, 0x2eb6b978c8793a8bull},
    {"all_dynamic", "recommended+probability", 4, 0x1670cfe1e06684bbull},
    {"all_dynamic", "dld_slam+fundamental+tracker", 4, 0x1670cfe1e06684bbull},
    {"walking", "none", 8, 0xdb6cfcccd251d5bbull},
    {"walking", "dld_slam", 8, 0xb27f6c41a43af634ull},
    {"walking", "rtd_slam", 8, 0x6d64cc2f0c3db000ull},
    {"walking", "zhu_2024", 8, 0x092ca26bbca118faull},
    {"walking", "dfd_slam", 8, 0xf602bd46ab433621ull},
    {"walking", "zhang_2023", 8, 0x58d80cb62d9d3f70ull},
    {"walking", "recommended", 8, 0x3e9f4f1fc0222375ull},
    {"walking", "recommended+multiview", 8, 0xffcbbfdefb8ede0dull},
    {"walking", "recommended+probability", 8, 0x0cb5ef9b04788480ull},
    {"walking", "dld_slam+fundamental+tracker", 8, 0x27e67c45ead4d37dull},
    {"seated", "none", 8, 0x69dc837b4cc728afull},
    {"seated", "dld_slam", 8, 0xf9f057552b93da8dull},
    {"seated", "rtd_slam", 8, 0x1be0a99db4a2a010ull},
    {"seated", "zhu_2024", 8, 0x70defefbdfbb7445ull},
    {"seated", "dfd_slam", 8, 0x56351946f0f66bfaull},
    {"seated", "zhang_2023", 8, 0xd3f4d06f8a44e25full},
    {"seated", "recommended", 8, 0xe43e51720f58a59bull},
    {"seated", "recommended+multiview", 8, 0xc4b7b2b08342fdd8ull},
    {"seated", "recommended+probability", 8, 0xbc4aa8e80091586cull},
    {"seated", "dld_slam+fundamental+tracker", 8, 0xaa062c671a913284ull},
    {"slow", "none", 8, 0xdb6cfcccd251d5bbull},
    {"slow", "dld_slam", 8, 0x5cdb057f7568ab2dull},
    {"slow", "rtd_slam", 8, 0x96c79b0f603c0d94ull},
    {"slow", "zhu_2024", 8, 0x092ca26bbca118faull},
    {"slow", "dfd_slam", 8, 0x123e71375096d5abull},
    {"slow", "zhang_2023", 8, 0x58d80cb62d9d3f70ull},
    {"slow", "recommended", 8, 0x1645b1afaf9865c2ull},
    {"slow", "recommended+multiview", 8, 0x5113f578f35fce42ull},
    {"slow", "recommended+probability", 8, 0x0b5641bbc2a3814cull},
    {"slow", "dld_slam+fundamental+tracker", 8, 0x75fe4de4efa8dd30ull},
    {"all_dynamic", "none", 8, 0x1670cfe1e06684bbull},
    {"all_dynamic", "dld_slam", 8, 0xa116d65eb6b05e0full},
    {"all_dynamic", "rtd_slam", 8, 0x0f53a341d0f1f5b9ull},
    {"all_dynamic", "zhu_2024", 8, 0x0f53a341d0f1f5b9ull},
    {"all_dynamic", "dfd_slam", 8, 0x1670cfe1e06684bbull},
    {"all_dynamic", "zhang_2023", 8, 0x0f53a341d0f1f5b9ull},
    {"all_dynamic", "recommended", 8, 0x2eb6b978c8793a8bull},
    {"all_dynamic", "recommended+multiview", 8, 0x2eb6b978c8793a8bull},
    {"all_dynamic", "recommended+probability", 8, 0x1670cfe1e06684bbull},
    {"all_dynamic", "dld_slam+fundamental+tracker", 8, 0x1670cfe1e06684bbull},
};

template <class T>
void check_sequence(const char* name, const SceneConfig& config, std::string* table) {
  const auto seq = golden_sequence<T>(config, 6);
  for (const auto& p : golden_presets<T>()) {
    const std::uint64_t got = hash_run(seq, config, p.options);
    char line[200];
    std::snprintf(line, sizeof line, "    {\"%s\", \"%s\", %d, 0x%016llxull},\n", name, p.name,
                  static_cast<int>(sizeof(T)), static_cast<unsigned long long>(got));
    *table += line;
    if (!kCompareHashes) continue;
    bool found = false;
    for (const Golden& g : kGolden) {
      if (std::string(g.sequence) != name || std::string(g.preset) != p.name || g.scalar_bytes != int(sizeof(T)))
        continue;
      found = true;
      EXPECT_EQ(got, g.hash) << name << " / " << p.name;
    }
    EXPECT_TRUE(found) << "no recorded hash for " << name << " / " << p.name;
  }
}

template <class T>
void check_all() {
  std::string table;
  SceneConfig walking;
  check_sequence<T>("walking", walking, &table);
  check_sequence<T>("seated", test::seated_person_config(), &table);
  SceneConfig slow;
  slow.walk_speed_m = 0.01;
  slow.sway_scale = 0.3;
  check_sequence<T>("slow", slow, &table);
  SceneConfig crowded;
  crowded.all_dynamic = true;
  check_sequence<T>("all_dynamic", crowded, &table);
  if (::testing::Test::HasFailure()) std::printf("%s", table.c_str());
  if (!kCompareHashes) GTEST_SKIP() << "hashes recorded with g++: sequences run, not compared";
}

TEST(PipelineGolden, FloatLabelsAndReasonsOfEveryPresetMatchTheRecordedOnes) { check_all<float>(); }
TEST(PipelineGolden, DoubleLabelsAndReasonsOfEveryPresetMatchTheRecordedOnes) { check_all<double>(); }

}  // namespace
}  // namespace dyncull
