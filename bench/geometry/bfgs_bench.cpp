// The small fixed-size BFGS (DFD-SLAM, Qian et al. 2024, eq. 10-14) on two standard problems against Ceres'
// GradientProblemSolver with the BFGS direction, same start, same objective code: the 2-D Rosenbrock
// function from (-1.2, 1) and a 6-D ill-conditioned quadratic (condition number 1e4).
// Counters: iterations, evaluations, and distance to the known minimiser.
#include "dyncull/geometry/bfgs.hpp"

#include <benchmark/benchmark.h>

#include <Eigen/Core>

#include <cmath>

#ifdef DYNCULL_HAS_CERES
#include <ceres/ceres.h>
#endif

namespace {

// f = (1 - x)^2 + 100 (y - x^2)^2, minimum 0 at (1, 1).
struct Rosenbrock {
  static constexpr int kN = 2;
  template <class T>
  T operator()(const Eigen::Matrix<T, 2, 1>& x, Eigen::Matrix<T, 2, 1>* g) const {
    const T a = T(1) - x(0), b = x(1) - x(0) * x(0);
    (*g)(0) = T(-2) * a - T(400) * x(0) * b;
    (*g)(1) = T(200) * b;
    return a * a + T(100) * b * b;
  }
  static Eigen::Matrix<double, 2, 1> start() { return Eigen::Matrix<double, 2, 1>(-1.2, 1.0); }
  static Eigen::Matrix<double, 2, 1> minimiser() { return Eigen::Matrix<double, 2, 1>(1.0, 1.0); }
};

// f = 1/2 sum_i c_i (x_i - i)^2 with c_i from 1 to 1e4 (log-spaced), minimum at (0, 1, ..., 5).
struct Quadratic6 {
  static constexpr int kN = 6;
  template <class T>
  T operator()(const Eigen::Matrix<T, 6, 1>& x, Eigen::Matrix<T, 6, 1>* g) const {
    T f = T(0);
    for (int i = 0; i < 6; ++i) {
      const T c = T(std::pow(10.0, 0.8 * i)), d = x(i) - T(i);
      (*g)(i) = c * d;
      f += T(0.5) * c * d * d;
    }
    return f;
  }
  static Eigen::Matrix<double, 6, 1> start() { return Eigen::Matrix<double, 6, 1>::Constant(10.0); }
  static Eigen::Matrix<double, 6, 1> minimiser() {
    Eigen::Matrix<double, 6, 1> m;
    m << 0, 1, 2, 3, 4, 5;
    return m;
  }
};

template <class Problem>
void BM_Dyncull_Bfgs(benchmark::State& state) {
  const Problem f;
  const auto x0 = Problem::start();
  dyncull::BfgsResult<double, Problem::kN> r;
  for (auto _ : state) {
    r = dyncull::bfgs_minimize(f, x0);
    benchmark::DoNotOptimize(r.x.data());
  }
  state.counters["ok"] = r.ok();
  state.counters["iterations"] = r.iterations;
  state.counters["evaluations"] = r.evaluations;
  state.counters["err_x"] = (r.x - Problem::minimiser()).norm();
}
BENCHMARK_TEMPLATE(BM_Dyncull_Bfgs, Rosenbrock)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Dyncull_Bfgs, Quadratic6)->Unit(benchmark::kMicrosecond);

#ifdef DYNCULL_HAS_CERES
template <class Problem>
class CeresObjective final : public ceres::FirstOrderFunction {
 public:
  bool Evaluate(const double* x, double* cost, double* gradient) const override {
    const Eigen::Map<const Eigen::Matrix<double, Problem::kN, 1>> xv(x);
    Eigen::Matrix<double, Problem::kN, 1> g;
    cost[0] = Problem()(Eigen::Matrix<double, Problem::kN, 1>(xv), &g);
    if (gradient)
      for (int i = 0; i < Problem::kN; ++i) gradient[i] = g(i);
    return true;
  }
  int NumParameters() const override { return Problem::kN; }
};

template <class Problem>
void BM_Ceres_Bfgs(benchmark::State& state) {
  ceres::GradientProblem problem(new CeresObjective<Problem>());
  ceres::GradientProblemSolver::Options o;  // Ceres defaults, BFGS direction
  o.line_search_direction_type = ceres::BFGS;
  o.logging_type = ceres::SILENT;
  ceres::GradientProblemSolver::Summary summary;
  Eigen::Matrix<double, Problem::kN, 1> x;
  for (auto _ : state) {
    x = Problem::start();
    ceres::Solve(o, problem, x.data(), &summary);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["ok"] = summary.IsSolutionUsable();
  state.counters["iterations"] = static_cast<double>(summary.iterations.size());
  state.counters["evaluations"] = summary.num_cost_evaluations + summary.num_gradient_evaluations;
  state.counters["err_x"] = (x - Problem::minimiser()).norm();
}
BENCHMARK_TEMPLATE(BM_Ceres_Bfgs, Rosenbrock)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_Ceres_Bfgs, Quadratic6)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace

BENCHMARK_MAIN();
