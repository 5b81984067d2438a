// The generic LO-RANSAC engine on a problem OpenCV also solves with RANSAC: a 2-D affine map from
// 1000 correspondences (0.5 px noise, 30 % or 60 % outliers), ours with a 20-line estimator (3-point
// minimal solve, least-squares refit) against cv::estimateAffine2D (RANSAC, same threshold and
// confidence, one thread). Counters: inlier recall / precision and the RMS error of the true inliers.
#include "dyncull/core/random.hpp"
#include "dyncull/geometry/ransac.hpp"

#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

#include <cmath>
#include <cstdint>
#include <vector>

#ifdef DYNCULL_HAS_OPENCV
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#endif

namespace {

using Affine = Eigen::Matrix<double, 2, 3>;

struct Data {
  std::vector<Eigen::Vector2d> src, dst;
  std::vector<std::uint8_t> inlier;
  Affine truth;
};

Data make_data(double outlier_fraction) {
  dyncull::Random rng(17);
  Data d;
  d.truth << 0.96, -0.21, 30.0, 0.18, 1.03, -12.0;
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector2d p(rng.uniform(0, 640), rng.uniform(0, 480));
    Eigen::Vector2d q = d.truth.leftCols<2>() * p + d.truth.col(2);
    const bool in = rng.uniform() >= outlier_fraction;
    if (in) {
      q += 0.5 * Eigen::Vector2d(rng.normal(), rng.normal());
    } else {
      q = Eigen::Vector2d(rng.uniform(0, 640), rng.uniform(0, 480));
    }
    d.src.push_back(p);
    d.dst.push_back(q);
    d.inlier.push_back(in);
  }
  return d;
}

const Data& data(int outlier_percent) {
  static const Data d30 = make_data(0.3), d60 = make_data(0.6);
  return outlier_percent == 30 ? d30 : d60;
}

// Everything the engine needs from a user: sample size, minimal solve, squared residuals, refit.
class AffineEstimator {
 public:
  using Model = Affine;
  using Scalar = double;
  static constexpr int kSampleSize = 3;
  static constexpr int kMaxModels = 1;
  explicit AffineEstimator(const Data& d) : d_(d) {}
  std::size_t num_data() const { return d_.src.size(); }
  int minimal_solve(const std::uint32_t* s, Model* m) const { return refit(s, 3, m) ? 1 : 0; }
  void residuals_sq(const Model& m, double* out) const {
    for (std::size_t i = 0; i < d_.src.size(); ++i)
      out[i] = (m.leftCols<2>() * d_.src[i] + m.col(2) - d_.dst[i]).squaredNorm();
  }
  bool refit(const std::uint32_t* idx, std::size_t n, Model* m) const {
    Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
    Eigen::Matrix<double, 3, 2> Atb = Eigen::Matrix<double, 3, 2>::Zero();
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d a(d_.src[idx[k]].x(), d_.src[idx[k]].y(), 1.0);
      AtA.noalias() += a * a.transpose();
      Atb.noalias() += a * d_.dst[idx[k]].transpose();
    }
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(AtA);
    if (lu.rank() < 3) return false;  // collinear sample
    *m = lu.solve(Atb).transpose();
    return m->allFinite();
  }

 private:
  const Data& d_;
};

void accuracy(benchmark::State& state, const Data& d, const Affine& m, const std::vector<std::uint8_t>& mask) {
  std::size_t tp = 0, fp = 0, fn = 0;
  double sq = 0;
  std::size_t inliers = 0;
  for (std::size_t i = 0; i < d.src.size(); ++i) {
    tp += mask[i] && d.inlier[i];
    fp += mask[i] && !d.inlier[i];
    fn += !mask[i] && d.inlier[i];
    if (!d.inlier[i]) continue;
    const Eigen::Vector2d noise_free = d.truth.leftCols<2>() * d.src[i] + d.truth.col(2);
    sq += (m.leftCols<2>() * d.src[i] + m.col(2) - noise_free).squaredNorm();
    ++inliers;
  }
  state.counters["recall"] = double(tp) / double(tp + fn);
  state.counters["precision"] = tp + fp ? double(tp) / double(tp + fp) : 1.0;
  state.counters["rms_vs_truth_px"] = std::sqrt(sq / double(inliers));
}

void BM_Dyncull_RansacAffine(benchmark::State& state) {
  const Data& d = data(int(state.range(0)));
  const AffineEstimator est(d);
  dyncull::RansacOptions o;
  o.max_residual = 2.0;
  o.confidence = 0.99;
  o.max_iterations = 2000;
  o.seed = 3;
  dyncull::RansacResult<Affine> r;
  for (auto _ : state) {
    r = dyncull::ransac(est, o);
    benchmark::DoNotOptimize(r.model.data());
  }
  accuracy(state, d, r.model, r.inlier_mask);
  state.counters["iterations"] = double(r.iterations);
}
BENCHMARK(BM_Dyncull_RansacAffine)->Arg(30)->Arg(60)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_OPENCV
void BM_OpenCV_EstimateAffine2D(benchmark::State& state) {
  cv::setNumThreads(1);
  const Data& d = data(int(state.range(0)));
  std::vector<cv::Point2f> src, dst;
  for (std::size_t i = 0; i < d.src.size(); ++i) {
    src.emplace_back(float(d.src[i].x()), float(d.src[i].y()));
    dst.emplace_back(float(d.dst[i].x()), float(d.dst[i].y()));
  }
  cv::Mat A;
  std::vector<std::uint8_t> mask;
  for (auto _ : state) {
    // Default refineIters = 10 (Levenberg-Marquardt on the inliers), as a user would call it.
    A = cv::estimateAffine2D(src, dst, mask, cv::RANSAC, 2.0, 2000, 0.99);
    benchmark::DoNotOptimize(A.data);
  }
  Affine m = Affine::Zero();
  if (!A.empty())
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 3; ++c) m(r, c) = A.at<double>(r, c);
  accuracy(state, d, m, mask);
}
BENCHMARK(BM_OpenCV_EstimateAffine2D)->Arg(30)->Arg(60)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace

BENCHMARK_MAIN();
