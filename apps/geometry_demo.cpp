// geometry_demo: dyncull's geometry on synthetic data, side by side with OpenCV.
//   F-RANSAC    dyncull::estimate_fundamental_ransac  vs cv::findFundamentalMat(USAC_FAST)
//   PnP-RANSAC  dyncull::solve_pnp_ransac             vs cv::solvePnPRansac(SOLVEPNP_P3P)
//   rotation    dyncull::estimate_rotation_centre (DFD-SLAM, Qian et al. 2024, Algorithm 2; no OpenCV equivalent)
// Data: 640x480 pinhole camera (fx = fy = 535), 0.5 px noise, 30 % outliers (20 % for the rotation).
// Times are medians over repeated runs of one thread on this machine; accuracy is against the truth.
// Usage: geometry_demo [num_points=1000] [repeats=15]
#include "dyncull/core/camera.hpp"
#include "dyncull/core/random.hpp"
#include "dyncull/culling/descriptor_switch.hpp"
#include "dyncull/geometry/fundamental.hpp"
#include "dyncull/geometry/pnp.hpp"
#include "dyncull/geometry/rotation_centre.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

/// Median wall time (ms) of `repeats` calls of fn.
template <class Fn>
double median_ms(int repeats, Fn&& fn) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = Clock::now();
    fn();
    t.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  std::nth_element(t.begin(), t.begin() + static_cast<std::ptrdiff_t>(t.size() / 2), t.end());
  return t[t.size() / 2];
}

Eigen::Matrix3d rotation(double rx, double ry, double rz) {
  return (Eigen::AngleAxisd(rz, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(ry, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rx, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

double rotation_error_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return dyncull::rotation_angle(Eigen::Matrix3d(a.transpose() * b)) * 180.0 / M_PI;
}

/// Sampson distance (px) of a correspondence under F.
double sampson(const Eigen::Matrix3d& F, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector3d x1(a.x(), a.y(), 1), x2(b.x(), b.y(), 1);
  const Eigen::Vector3d Fx1 = F * x1, Ftx2 = F.transpose() * x2;
  const double e = x2.dot(Fx1);
  return std::abs(e) / std::sqrt(Fx1.x() * Fx1.x() + Fx1.y() * Fx1.y() + Ftx2.x() * Ftx2.x() + Ftx2.y() * Ftx2.y());
}

struct Row {
  std::string method;
  double ms = 0;
  std::string accuracy;
};

void print_table(const char* title, const std::vector<Row>& rows) {
  std::printf("\n%s\n", title);
  std::printf("  %-44s %10s   %s\n", "method", "median ms", "accuracy");
  for (const auto& r : rows) std::printf("  %-44s %10.3f   %s\n", r.method.c_str(), r.ms, r.accuracy.c_str());
}

std::string fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

// ------------------------------------------------------------------------------------------------

void fundamental_demo(int n, int repeats) {
  const dyncull::PinholeCamera<double> cam{535, 535, 319.5, 239.5, 640, 480};
  dyncull::Random rng(1);
  dyncull::Rigid3<double> cam2_from_cam1;
  cam2_from_cam1.R = rotation(0.02, -0.05, 0.03);
  cam2_from_cam1.t = Eigen::Vector3d(0.3, 0.05, 0.02);
  std::vector<Eigen::Vector2d> p1, p2, clean1, clean2;
  std::vector<bool> inlier;
  while (static_cast<int>(p1.size()) < n) {
    const Eigen::Vector3d X(rng.uniform(-2, 2), rng.uniform(-1.5, 1.5), rng.uniform(2, 8));
    const Eigen::Vector3d X2 = cam2_from_cam1.apply(X);
    const Eigen::Vector2d a = cam.project(X), b = cam.project(X2);
    if (!cam.in_image(a.x(), a.y()) || !cam.in_image(b.x(), b.y()) || X2.z() <= 0) continue;
    const bool is_inlier = rng.uniform() >= 0.3;
    clean1.push_back(a);
    clean2.push_back(b);
    p1.push_back(a + 0.5 * Eigen::Vector2d(rng.normal(), rng.normal()));
    p2.push_back(is_inlier ? Eigen::Vector2d(b + 0.5 * Eigen::Vector2d(rng.normal(), rng.normal()))
                           : Eigen::Vector2d(rng.uniform(0, 639), rng.uniform(0, 479)));
    inlier.push_back(is_inlier);
  }
  // Accuracy: RMS Sampson distance of the noise-free true correspondences under the estimate (0 = exact
  // F), and recall / precision of the inlier labels.
  auto score = [&](const Eigen::Matrix3d& F, const std::vector<std::uint8_t>& mask) {
    double sq = 0;
    std::size_t m = 0, tp = 0, labelled = 0, truth = 0;
    for (std::size_t i = 0; i < p1.size(); ++i) {
      if (inlier[i]) {
        sq += std::pow(sampson(F, clean1[i], clean2[i]), 2);
        ++m;
        ++truth;
        tp += mask[i] != 0;
      }
      labelled += mask[i] != 0;
    }
    return fmt("F rms %.3f px, recall %.3f, precision %.3f", std::sqrt(sq / double(m)), double(tp) / double(truth),
               double(tp) / double(std::max<std::size_t>(1, labelled)));
  };

  std::vector<Row> rows;
  dyncull::FundamentalOptions<double> fo;
  fo.ransac.max_residual = 1.0;
  dyncull::FundamentalResult<double> ours;
  const double t_ours = median_ms(repeats, [&] { ours = dyncull::estimate_fundamental_ransac(p1, p2, fo); });
  rows.push_back({"dyncull::estimate_fundamental_ransac (1 px)", t_ours,
                  ours.F.allFinite() ? score(ours.F, ours.inlier_mask) : std::string("failed: ") + ours.reason});

  std::vector<cv::Point2f> c1, c2;
  for (std::size_t i = 0; i < p1.size(); ++i) {
    c1.emplace_back(float(p1[i].x()), float(p1[i].y()));
    c2.emplace_back(float(p2[i].x()), float(p2[i].y()));
  }
  cv::Mat Fcv, mask;
  const double t_cv = median_ms(repeats, [&] { Fcv = cv::findFundamentalMat(c1, c2, cv::USAC_FAST, 1.0, 0.99, 10000, mask); });
  if (Fcv.rows == 3 && Fcv.cols == 3) {
    Eigen::Matrix3d F;
    cv::cv2eigen(Fcv, F);
    std::vector<std::uint8_t> m(mask.begin<std::uint8_t>(), mask.end<std::uint8_t>());
    rows.push_back({"cv::findFundamentalMat USAC_FAST (1 px)", t_cv, score(F, m)});
  } else {
    rows.push_back({"cv::findFundamentalMat USAC_FAST (1 px)", t_cv, "failed"});
  }
  print_table(fmt("F-RANSAC, %.0f correspondences, 30 %% outliers, 0.5 px noise", double(n)).c_str(), rows);
  std::printf("  ratio time dyncull / OpenCV: %.2f\n", t_ours / t_cv);
}

// ------------------------------------------------------------------------------------------------

void pnp_demo(int n, int repeats) {
  const dyncull::PinholeCamera<double> cam{535, 535, 319.5, 239.5, 640, 480};
  dyncull::Random rng(2);
  dyncull::Rigid3<double> truth;
  truth.R = rotation(0.1, -0.2, 0.05);
  truth.t = Eigen::Vector3d(0.1, -0.2, 0.5);
  std::vector<Eigen::Vector3d> world;
  std::vector<Eigen::Vector2d> pixels;
  while (static_cast<int>(world.size()) < n) {
    const Eigen::Vector3d Xc(rng.uniform(-2, 2), rng.uniform(-1.5, 1.5), rng.uniform(1.5, 6));
    const Eigen::Vector2d uv = cam.project(Xc);
    if (!cam.in_image(uv.x(), uv.y())) continue;
    world.push_back(truth.inverse().apply(Xc));
    pixels.push_back(rng.uniform() < 0.3 ? Eigen::Vector2d(rng.uniform(0, 639), rng.uniform(0, 479))
                                         : Eigen::Vector2d(uv + 0.5 * Eigen::Vector2d(rng.normal(), rng.normal())));
  }
  auto score = [&](const Eigen::Matrix3d& R, const Eigen::Vector3d& t, std::size_t inliers) {
    return fmt("rot err %.4f deg, trans err %.2f mm, inliers %.0f", rotation_error_deg(R, truth.R),
               1000.0 * (t - truth.t).norm(), double(inliers));
  };
  std::vector<Row> rows;
  dyncull::PnpOptions<double> po;  // 2 px threshold, LM refinement
  dyncull::PnpResult<double> ours;
  const double t_ours = median_ms(repeats, [&] { ours = dyncull::solve_pnp_ransac(world, pixels, cam, po); });
  rows.push_back({"dyncull::solve_pnp_ransac (P3P, 2 px, LM)", t_ours,
                  ours.ok() ? score(ours.cam_from_world.R, ours.cam_from_world.t, ours.num_inliers)
                            : std::string("failed: ") + ours.reason});

  std::vector<cv::Point3f> cw;
  std::vector<cv::Point2f> cp;
  for (std::size_t i = 0; i < world.size(); ++i) {
    cw.emplace_back(float(world[i].x()), float(world[i].y()), float(world[i].z()));
    cp.emplace_back(float(pixels[i].x()), float(pixels[i].y()));
  }
  cv::Mat K;
  cv::eigen2cv(Eigen::Matrix3d(cam.K()), K);
  cv::Mat rvec, tvec;
  std::vector<int> inl;
  bool cv_ok = false;
  const double t_cv = median_ms(repeats, [&] {
    cv_ok = cv::solvePnPRansac(cw, cp, K, cv::noArray(), rvec, tvec, false, 1000, 2.0f, 0.99, inl, cv::SOLVEPNP_P3P);
  });
  if (cv_ok) {
    cv::Mat Rcv;
    cv::Rodrigues(rvec, Rcv);
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    cv::cv2eigen(Rcv, R);
    cv::cv2eigen(tvec, t);
    rows.push_back({"cv::solvePnPRansac SOLVEPNP_P3P (2 px)", t_cv, score(R, t, inl.size())});
  } else {
    rows.push_back({"cv::solvePnPRansac SOLVEPNP_P3P (2 px)", t_cv, "failed"});
  }
  print_table(fmt("PnP-RANSAC, %.0f points, 30 %% outliers, 0.5 px noise", double(n)).c_str(), rows);
  std::printf("  ratio time dyncull / OpenCV: %.2f\n", t_ours / t_cv);
}

// ------------------------------------------------------------------------------------------------

void rotation_demo(int repeats) {
  const Eigen::Vector2d centre(340, 230);
  const double angle = 25.0 * M_PI / 180.0;
  dyncull::Random rng(3);
  std::vector<Eigen::Vector2d> p1, p2;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector2d a(rng.uniform(0, 639), rng.uniform(0, 479));
    p1.push_back(a);
    if (rng.uniform() < 0.2) {  // a person walking right: translation, not rotation
      p2.push_back(a + Eigen::Vector2d(20 + rng.normal(), 2 + rng.normal()));
      continue;
    }
    const Eigen::Vector2d d = a - centre;
    p2.push_back(centre + Eigen::Vector2d(std::cos(angle) * d.x() - std::sin(angle) * d.y(),
                                          std::sin(angle) * d.x() + std::cos(angle) * d.y()) +
                 0.5 * Eigen::Vector2d(rng.normal(), rng.normal()));
  }
  std::vector<Row> rows;
  auto run = [&](const char* name, dyncull::RotationCentreOptions o) {
    dyncull::RotationCentreResult<double> r;
    const double t = median_ms(repeats, [&] { r = dyncull::estimate_rotation_centre(p1, p2, 640, 480, o); });
    rows.push_back({name, t,
                    r.ok() ? fmt("centre err %.3f px, angle %.3f deg, eq.15 inliers %.0f", (r.centre - centre).norm(),
                                 r.angle_deg(), double(r.num_inliers)) +
                                 " -> " + dyncull::to_string(dyncull::choose_descriptor(r))
                           : std::string("no rotation: ") + r.reason});
  };
  dyncull::RotationCentreOptions exact;
  run("normal equations (eq. 5, default)", exact);
  dyncull::RotationCentreOptions bfgs;
  bfgs.solver = dyncull::RotationCentreSolver::Bfgs;
  run("BFGS from the image centre (paper)", bfgs);
  dyncull::RotationCentreOptions huber;
  huber.loss = dyncull::RobustLoss::Huber;
  huber.loss_scale_px = 2.0;
  run("IRLS Huber 2 px", huber);
  dyncull::RotationCentreOptions cauchy = huber;
  cauchy.loss = dyncull::RobustLoss::Cauchy;
  run("IRLS Cauchy 2 px", cauchy);
  print_table("Frame rotation (DFD-SLAM Alg. 2), 500 flow vectors, 25 deg about (340, 230), 20 % translating", rows);
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::max(20, std::atoi(argv[1])) : 1000;
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 15;
  cv::setNumThreads(1);  // compare single-threaded code with single-threaded code
  std::printf("dyncull geometry demo: %d points, median of %d runs (one thread; OpenCV %s)\n", n, repeats,
              CV_VERSION);
  fundamental_demo(n, repeats);
  pnp_demo(n, repeats);
  rotation_demo(repeats);
  return 0;
}
