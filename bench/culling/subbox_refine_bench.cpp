// Sub-box refinement (DFD-SLAM Algorithm 1) at ~1100 features and 4 boxes: the vote against its floor
// (one pass binning the features into the boxes' 3x3 cells, nothing else), and the raster mask with its
// 15 px dilation against cv::dilate with the same 31x31 rectangle on the same pixels.
#include "dyncull/culling/moving_consistency.hpp"
#include "dyncull/culling/subbox_refine.hpp"

#include "support/culling_scenes.hpp"

#include <benchmark/benchmark.h>

#include <array>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#endif

namespace {
using namespace dyncull;

struct Data {
  test::CullingScene<float> scene;
  std::vector<FeatureLabel> geometric;  // epipolar labels of the moving-consistency check (the input of Alg. 1)
  std::vector<Detection<float>> boxes;  // person / chair boxes, as the pipeline passes them
};

const Data& data() {
  static const Data d = [] {
    Data x;
    test::SceneConfig config;
    config.num_uniform = 760;
    x.scene = test::make_culling_scene<float>(config);
    std::vector<std::uint8_t> in_box(x.scene.size(), 0);
    for (const auto& det : x.scene.detections) {
      if (det.class_id != 0 && det.class_id != 56) continue;
      x.boxes.push_back(det);
      for (std::size_t i = 0; i < x.scene.size(); ++i)
        if (det.box.contains(x.scene.keypoints[i].x(), x.scene.keypoints[i].y())) in_box[i] = 1;
    }
    MovingConsistencyOptions<float> o;
    x.geometric = check_moving_consistency(x.scene.prev_keypoints, x.scene.keypoints, o, x.scene.track_valid,
                                           in_box)
                      .labels;
    return x;
  }();
  return d;
}

void BM_SubBox_Vote_Dyncull(benchmark::State& state) {
  const Data& d = data();
  SubBoxOptions<float> o;
  SubBoxResult<float> r;
  for (auto _ : state) {
    refine_subboxes(d.scene.keypoints, d.geometric, d.boxes, o, &r);
    benchmark::DoNotOptimize(r.labels.data());
  }
  std::vector<std::uint8_t> pred(r.labels.size());
  for (std::size_t i = 0; i < pred.size(); ++i) pred[i] = r.labels[i] == FeatureLabel::Dynamic;
  const auto pr = test::precision_recall(pred, d.scene.truth_dynamic, pred.size());
  std::vector<std::uint8_t> geo(d.geometric.size());
  for (std::size_t i = 0; i < geo.size(); ++i) geo[i] = d.geometric[i] == FeatureLabel::Dynamic;
  const auto pr_geo = test::precision_recall(geo, d.scene.truth_dynamic, geo.size());
  state.counters["features"] = double(pred.size());
  state.counters["boxes"] = double(d.boxes.size());
  state.counters["precision"] = pr.precision;
  state.counters["recall"] = pr.recall;
  state.counters["epipolar_precision"] = pr_geo.precision;
  state.counters["epipolar_recall"] = pr_geo.recall;
  state.counters["whole_boxes"] = double(r.num_whole_boxes);
}
BENCHMARK(BM_SubBox_Vote_Dyncull)->Unit(benchmark::kMicrosecond);

// Floor: bin every feature into the 3x3 cells of every box and count dynamic / static votes. Any
// implementation of Algorithm 1 does at least this; the rest (merging, sigma2, relabelling) is on top.
void BM_SubBox_Vote_Floor(benchmark::State& state) {
  const Data& d = data();
  std::vector<std::array<std::uint32_t, 18>> counts(d.boxes.size());
  for (auto _ : state) {
    for (auto& c : counts) c.fill(0);
    for (std::size_t b = 0; b < d.boxes.size(); ++b) {
      const Box<float>& box = d.boxes[b].box;
      for (std::size_t i = 0; i < d.scene.keypoints.size(); ++i) {
        const float x = d.scene.keypoints[i].x(), y = d.scene.keypoints[i].y();
        if (!box.contains(x, y)) continue;
        const int cell = detail::subbox_cell(box, 3, x, y);
        if (cell < 0) continue;
        ++counts[b][static_cast<std::size_t>(cell) + (d.geometric[i] == FeatureLabel::Dynamic ? 0 : 9)];
      }
    }
    benchmark::DoNotOptimize(counts.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_SubBox_Vote_Floor)->Unit(benchmark::kMicrosecond);

// The raster mask of Algorithm 1: dynamic cells (whole cells: no object mask) dilated by 15 px.
void BM_SubBox_Mask_Dyncull(benchmark::State& state) {
  const Data& d = data();
  const auto r = refine_subboxes(d.scene.keypoints, d.geometric, d.boxes, SubBoxOptions<float>{});
  Mask mask(d.scene.width, d.scene.height);
  std::vector<std::uint16_t> scratch;
  std::size_t set = 0;
  for (auto _ : state) {
    set = subbox_mask(r, d.boxes, SubBoxOptions<float>{}, ConstMaskView{}, mask.view(), &scratch);
    benchmark::DoNotOptimize(mask.pixels.data());
  }
  state.counters["pixels_set"] = double(set);
}
BENCHMARK(BM_SubBox_Mask_Dyncull)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
// Peer: the same undilated cells drawn into a cv::Mat, then cv::dilate with a 31x31 rectangle on the
// whole image (what the forks do), same pixels set.
void BM_SubBox_Mask_PeerCvDilate(benchmark::State& state) {
  const Data& d = data();
  const auto r = refine_subboxes(d.scene.keypoints, d.geometric, d.boxes, SubBoxOptions<float>{});
  SubBoxOptions<float> undilated;
  undilated.dilation_radius_px = 0;
  Mask cells(d.scene.width, d.scene.height);
  std::vector<std::uint16_t> scratch;
  subbox_mask(r, d.boxes, undilated, ConstMaskView{}, cells.view(), &scratch);
  const cv::Mat src(cells.height, cells.width, CV_8UC1, cells.pixels.data());
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(31, 31));
  cv::Mat dst;
  for (auto _ : state) {
    cv::dilate(src, dst, kernel);
    benchmark::DoNotOptimize(dst.data);
  }
  // Same result as ours?
  Mask ours(d.scene.width, d.scene.height);
  subbox_mask(r, d.boxes, SubBoxOptions<float>{}, ConstMaskView{}, ours.view(), &scratch);
  std::size_t differ = 0;
  for (int v = 0; v < dst.rows; ++v)
    for (int u = 0; u < dst.cols; ++u) differ += (dst.at<std::uint8_t>(v, u) != 0) != ours.test(u, v);
  state.counters["pixels_set"] = double(cv::countNonZero(dst));
  state.counters["pixels_differing_from_ours"] = double(differ);
}
BENCHMARK(BM_SubBox_Mask_PeerCvDilate)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace

BENCHMARK_MAIN();
