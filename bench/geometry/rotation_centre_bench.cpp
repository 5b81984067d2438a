// Rotation centre (DFD-SLAM, Qian et al. 2024, Algorithm 2) on 500 noisy flow vectors: our exact 2x2 solve and our BFGS
// against Ceres' GradientProblemSolver (BFGS) on the same normalised bisectors, from the image centre.
// Counters: distance to the tightly converged Ceres minimiser (px) and to the true centre (px).
#include "dyncull/geometry/rotation_centre.hpp"

#include "dyncull/core/random.hpp"

#include <benchmark/benchmark.h>

#ifdef DYNCULL_HAS_CERES
#include <ceres/ceres.h>
#endif

#include <cmath>
#include <vector>

namespace {

struct FlowData {
  std::vector<Eigen::Vector2d> p1, p2;
  Eigen::Vector2d truth{350.0, 210.0};
  Eigen::Vector2d start{319.5, 239.5};
  dyncull::BisectorLines<double> lines;
};

/// n vectors: 0.5 rad rotation about `truth`, 0.5 px noise, and `outlier_fraction` translating vectors.
FlowData make_flow(std::size_t n, double outlier_fraction = 0.0) {
  FlowData d;
  dyncull::Random rng(42);
  const double c = std::cos(0.3), s = std::sin(0.3);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = rng.uniform(0, 639), y = rng.uniform(0, 479);
    d.p1.emplace_back(x, y);
    if (rng.uniform() < outlier_fraction) {
      d.p2.emplace_back(x + 25 + rng.normal(), y + 3 + rng.normal());
      continue;
    }
    const double dx = x - d.truth.x(), dy = y - d.truth.y();
    d.p2.emplace_back(d.truth.x() + c * dx - s * dy + 0.5 * rng.normal(), d.truth.y() + s * dx + c * dy + 0.5 * rng.normal());
  }
  dyncull::make_bisector_lines(d.p1, d.p2, d.start, 0.5, &d.lines);
  return d;
}

#ifdef DYNCULL_HAS_CERES
class BisectorObjective final : public ceres::FirstOrderFunction {
 public:
  explicit BisectorObjective(const dyncull::BisectorLines<double>* lines) : lines_(lines) {}
  bool Evaluate(const double* x, double* cost, double* gradient) const override {
    Eigen::Vector2d g;
    cost[0] = dyncull::bisector_cost(*lines_, Eigen::Vector2d(x[0], x[1]), dyncull::RobustLoss::None, 3.0, &g);
    if (gradient) {
      gradient[0] = g.x();
      gradient[1] = g.y();
    }
    return true;
  }
  int NumParameters() const override { return 2; }

 private:
  const dyncull::BisectorLines<double>* lines_;
};

Eigen::Vector2d ceres_minimiser(const FlowData& d, bool tight, int* iterations = nullptr) {
  FLAGS_minloglevel = 2;  // the tight reference solve ends in line-search warnings at round-off level
  ceres::GradientProblem problem(new BisectorObjective(&d.lines));
  ceres::GradientProblemSolver::Options o;
  o.line_search_direction_type = ceres::BFGS;
  if (tight) {
    // Tight enough for a 1e-12 px reference, loose enough that Ceres' line search does not complain.
    o.function_tolerance = 1e-15;
    o.gradient_tolerance = 1e-11;
    o.parameter_tolerance = 1e-14;
  }
  ceres::GradientProblemSolver::Summary summary;
  double x[2] = {d.start.x(), d.start.y()};
  ceres::Solve(o, problem, x, &summary);
  if (iterations) *iterations = static_cast<int>(summary.iterations.size());
  return Eigen::Vector2d(x[0], x[1]);
}

void BM_CeresBfgs(benchmark::State& state) {
  const FlowData d = make_flow(static_cast<std::size_t>(state.range(0)));
  const Eigen::Vector2d reference = ceres_minimiser(d, true);
  ceres::GradientProblem problem(new BisectorObjective(&d.lines));
  ceres::GradientProblemSolver::Options o;  // Ceres defaults, BFGS direction as in the paper
  o.line_search_direction_type = ceres::BFGS;
  ceres::GradientProblemSolver::Summary summary;
  double x[2];
  for (auto _ : state) {
    x[0] = d.start.x();
    x[1] = d.start.y();
    ceres::Solve(o, problem, x, &summary);
    benchmark::DoNotOptimize(x);
  }
  state.counters["err_vs_ceres_px"] = (Eigen::Vector2d(x[0], x[1]) - reference).norm();
  state.counters["err_vs_truth_px"] = (Eigen::Vector2d(x[0], x[1]) - d.truth).norm();
  state.counters["iterations"] = static_cast<double>(summary.iterations.size());
}
BENCHMARK(BM_CeresBfgs)->Arg(500)->Arg(100)->Arg(2000);
#endif

template <class T>
void BM_NormalEquations(benchmark::State& state) {
  const FlowData d = make_flow(static_cast<std::size_t>(state.range(0)));
  dyncull::BisectorLines<T> lines;
  std::vector<dyncull::Vec2<T>> p1, p2;
  for (std::size_t i = 0; i < d.p1.size(); ++i) {
    p1.push_back(d.p1[i].cast<T>());
    p2.push_back(d.p2[i].cast<T>());
  }
  dyncull::make_bisector_lines(p1, p2, dyncull::Vec2<T>(d.start.cast<T>()), T(0.5), &lines);
  dyncull::CentreSolution<T> s;
  for (auto _ : state) {
    s = dyncull::solve_centre_normal_equations(lines);
    benchmark::DoNotOptimize(s.centre);
  }
#ifdef DYNCULL_HAS_CERES
  state.counters["err_vs_ceres_px"] = (s.centre.template cast<double>() - ceres_minimiser(d, true)).norm();
#endif
  state.counters["err_vs_truth_px"] = (s.centre.template cast<double>() - d.truth).norm();
}
BENCHMARK_TEMPLATE(BM_NormalEquations, double)->Arg(500)->Arg(100)->Arg(2000);
BENCHMARK_TEMPLATE(BM_NormalEquations, float)->Arg(500);

void BM_OurBfgs(benchmark::State& state) {
  const FlowData d = make_flow(static_cast<std::size_t>(state.range(0)));
  dyncull::CentreSolution<double> s;
  for (auto _ : state) {
    s = dyncull::solve_centre_bfgs(d.lines, d.start);
    benchmark::DoNotOptimize(s.centre);
  }
#ifdef DYNCULL_HAS_CERES
  state.counters["err_vs_ceres_px"] = (s.centre - ceres_minimiser(d, true)).norm();
#endif
  state.counters["err_vs_truth_px"] = (s.centre - d.truth).norm();
  state.counters["iterations"] = s.iterations;
}
BENCHMARK(BM_OurBfgs)->Arg(500)->Arg(100)->Arg(2000);

/// Robust variants with 30 % translating outliers: error against the true centre is the accuracy figure.
void BM_Robust(benchmark::State& state) {
  const FlowData d = make_flow(500, 0.3);
  const auto solver = state.range(0) == 0 ? dyncull::RotationCentreSolver::NormalEquations : dyncull::RotationCentreSolver::Bfgs;
  const auto loss = static_cast<dyncull::RobustLoss>(state.range(1));
  dyncull::CentreSolution<double> s;
  for (auto _ : state) {
    s = solver == dyncull::RotationCentreSolver::Bfgs
            ? dyncull::solve_centre_bfgs(d.lines, d.start, loss, 2.0)
            : dyncull::solve_centre_normal_equations(d.lines, loss, 2.0);
    benchmark::DoNotOptimize(s.centre);
  }
  state.SetLabel(std::string(dyncull::to_string(solver)) + "/" + dyncull::to_string(loss));
  state.counters["err_vs_truth_px"] = (s.centre - d.truth).norm();
  state.counters["iterations"] = s.iterations;
}
BENCHMARK(BM_Robust)->Args({0, 0})->Args({0, 1})->Args({0, 2})->Args({1, 1})->Args({1, 2});

/// The whole Algorithm 2 from point containers: bisectors, exact OP, eq. 15 filter, eq. 16 angle.
void BM_FullAlgorithm2(benchmark::State& state) {
  const FlowData d = make_flow(static_cast<std::size_t>(state.range(0)));
  dyncull::RotationCentreResult<double> r;
  for (auto _ : state) {
    r = dyncull::estimate_rotation_centre(d.p1, d.p2, 640, 480);
    benchmark::DoNotOptimize(r.centre);
  }
  state.counters["err_vs_truth_px"] = (r.centre - d.truth).norm();
  state.counters["angle_err_deg"] = std::abs(r.angle_deg() - 0.3 * 180.0 / M_PI);
  state.counters["inlier_fraction"] = double(r.num_inliers) / double(r.num_vectors);
}
BENCHMARK(BM_FullAlgorithm2)->Arg(500);

}  // namespace
