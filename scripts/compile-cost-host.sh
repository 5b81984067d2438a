#!/usr/bin/env bash
# Compile cost the compiled culler adds to a host front end: g++ -O2 -std=c++14 (ORB-SLAM3's standard)
# on a translation unit like an ORB-SLAM front end (opencv2/core, features2d and Eigen/Core; ORB on an
# image, keypoints and descriptors into vectors), once without dyncull and once including
# dyncull/opencv/culler.hpp (the OpenCV overloads of dyncull::Culler, compiled into dyncull::culler) and
# calling the culler, in one run. Prints user and wall time and
# peak RSS of each (/usr/bin/time -v) and the with/without ratios; fails when a ratio of user time or
# peak RSS exceeds --max-ratio (default 2).
#   scripts/compile-cost-host.sh [--csv FILE] [--max-ratio R] [--source DIR]
# --csv FILE writes "unit,user_s,wall_s,peak_rss_mb", one line per unit, for the docs.
set -euo pipefail
src="$(cd "$(dirname "$0")/.." && pwd)"
csv=""
max_ratio=2
while (($#)); do
  case "$1" in
    --csv) csv="$2"; shift 2 ;;
    --max-ratio) max_ratio="$2"; shift 2 ;;
    --source) src="$2"; shift 2 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "compile-cost-host.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
cxx="${CXX:-g++}"
opencv="$(pkg-config --cflags opencv4 2>/dev/null || echo -I/usr/include/opencv4)"
eigen="$(pkg-config --cflags eigen3 2>/dev/null || echo -I/usr/include/eigen3)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# The same front end twice; WITH_DYNCULL adds the include, the culler and its call.
cat > "$tmp/front_end.cpp" <<'CPP'
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#ifdef WITH_DYNCULL
#include <dyncull/opencv/culler.hpp>
#endif
#include <cstdio>
#include <vector>

struct Frame {
  std::vector<cv::KeyPoint> keys;
  cv::Mat descriptors;
  std::vector<float> depths;
  std::vector<Eigen::Vector3f> points;
};

int main() {
  cv::Mat gray(480, 640, CV_8UC1);
  cv::randu(gray, 0, 256);
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(2.f));
  const cv::Mat K = (cv::Mat_<float>(3, 3) << 525.f, 0.f, 319.5f, 0.f, 525.f, 239.5f, 0.f, 0.f, 1.f);
  cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  Frame f;
  orb->detectAndCompute(gray, cv::noArray(), f.keys, f.descriptors);
  for (const cv::KeyPoint& k : f.keys) {
    const float z = depth.at<float>(cvRound(k.pt.y), cvRound(k.pt.x));
    f.depths.push_back(z);
    f.points.push_back(Eigen::Vector3f((k.pt.x - 319.5f) * z / 525.f, (k.pt.y - 239.5f) * z / 525.f, z));
  }
#ifdef WITH_DYNCULL
  dyncull::Culler culler(dyncull::cv_adapter::culler_camera(K, cv::Size(640, 480)));
  std::vector<dyncull::DetectedBox> boxes(1, dyncull::cv_adapter::detected_box(cv::Rect2f(100, 100, 80, 200), 0));
  const cv::Mat Tcw = cv::Mat::eye(4, 4, CV_32F);
  const std::vector<std::uint8_t> keep = dyncull::cv_adapter::cull(culler, f.keys, f.descriptors, depth, boxes, &Tcw).keep;
  dyncull::cv_adapter::compact(keep, f.descriptors, f.keys, f.depths, f.points);
  std::printf("%s\n", culler.result().reason.c_str());
#endif
  std::printf("%zu features\n", f.keys.size());
  return K.empty() ? 1 : 0;
}
CPP

declare -A user wall rss
measure() {  # unit, extra flags...
  local unit=$1
  shift
  # shellcheck disable=SC2086
  /usr/bin/time -v "$cxx" -std=c++14 -O2 -Wall -Wextra -Werror $opencv $eigen -I"$src/include" "$@" \
    -c "$tmp/front_end.cpp" -o "$tmp/$unit.o" 2> "$tmp/$unit.time" || { cat "$tmp/$unit.time" >&2; exit 1; }
  user[$unit]=$(awk -F': ' '/User time/ {print $2}' "$tmp/$unit.time")
  local w
  w=$(awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' "$tmp/$unit.time")
  wall[$unit]=$(echo "$w" | awk -F: '{ s = 0; for (i = 1; i <= NF; ++i) s = s * 60 + $i; printf "%.2f", s }')
  rss[$unit]=$(awk -F': ' '/Maximum resident set size/ {printf "%.1f", $2 / 1024}' "$tmp/$unit.time")
  printf '%-22s user %6.2f s  wall %6.2f s  peak RSS %7.1f MB\n' "$unit" "${user[$unit]}" "${wall[$unit]}" "${rss[$unit]}"
}
measure host_front_end
measure host_front_end_culler -DWITH_DYNCULL

ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", (b > 0 ? a / b : 0) }'; }
r_user=$(ratio "${user[host_front_end_culler]}" "${user[host_front_end]}")
r_wall=$(ratio "${wall[host_front_end_culler]}" "${wall[host_front_end]}")
r_rss=$(ratio "${rss[host_front_end_culler]}" "${rss[host_front_end]}")
echo "ratio with/without the compiled culler: user ${r_user}x  wall ${r_wall}x  peak RSS ${r_rss}x (limit ${max_ratio}x on user time and peak RSS)"

if [[ -n "$csv" ]]; then
  {
    echo "unit,user_s,wall_s,peak_rss_mb"
    for unit in host_front_end host_front_end_culler; do
      echo "$unit,${user[$unit]},${wall[$unit]},${rss[$unit]}"
    done
  } > "$csv"
fi
awk -v u="$r_user" -v r="$r_rss" -v m="$max_ratio" 'BEGIN { exit !(u <= m && r <= m) }' || {
  echo "compile-cost-host.sh: including and calling the compiled culler costs more than ${max_ratio}x" >&2
  exit 1
}
