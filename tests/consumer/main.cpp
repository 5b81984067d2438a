// Consumer check: an installed header and the generated version header compile against the package's
// interface (its Eigen included) and compute a known answer. run_consumer_test.cmake checks that every
// header is installed; headers.standalone compiles each of them on its own.
#include <dyncull/core/camera.hpp>
#include <dyncull/version.hpp>

#include <cmath>
#include <cstdio>

int main() {
  const dyncull::PinholeCamera<double> camera{535.4, 539.2, 320.1, 247.6, 640, 480};
  const Eigen::Vector3d point(0.3, -0.2, 2.0);
  const Eigen::Vector2d pixel = camera.project(point);
  const Eigen::Vector3d back = camera.backproject(pixel, point.z());
  const double error = (back - point).norm();
  std::printf("dyncull %s consumer: round-trip error %.3g\n", DYNCULL_VERSION_STRING, error);
  return error < 1e-12 ? 0 : 1;
}
