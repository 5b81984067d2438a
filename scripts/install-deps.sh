#!/usr/bin/env bash
# Installs dyncull's build, test, benchmark and figure dependencies from Debian 12 packages.
# Idempotent: installs only what is missing, so CI and repeated runs cost a few seconds.
#   scripts/install-deps.sh [--orbslam2] [--orbslam3 | --orbslam3-check]
#     --orbslam2: also what Pangolin needs for scripts/orbslam2.sh
#     --orbslam3: also what Pangolin and ORB-SLAM3 need for scripts/orbslam3.sh (Boost serialization, libcrypto)
#     --orbslam3-check: only what scripts/orbslam3.sh --compile-check needs (headers: Pangolin's GL, GLEW,
#       EGL and Boost's)
set -euo pipefail

packages=(g++ clang cmake make ninja-build pkg-config libeigen3-dev libopencv-dev libceres-dev doxygen graphviz
          libgtest-dev libgmock-dev libbenchmark-dev libnanoflann-dev locales
          python3 python3-matplotlib)  # python3-matplotlib: scripts/figures.py draws the docs' plots
# Open3D is an optional benchmark peer (ICP); set DYNCULL_WITH_OPEN3D=1 to install it.
if [[ "${DYNCULL_WITH_OPEN3D:-0}" == 1 ]]; then packages+=(libopen3d-dev); fi
# ORB-SLAM2 (scripts/orbslam2.sh) links Pangolin, which needs OpenGL, GLEW and EGL (headless backend).
# ORB-SLAM3 (scripts/orbslam3.sh) links the same Pangolin, Boost serialization and libcrypto (OpenSSL).
for option in "$@"; do
  case "$option" in
    --orbslam2) packages+=(libgl1-mesa-dev libglew-dev libegl-dev) ;;
    --orbslam3) packages+=(libgl1-mesa-dev libglew-dev libegl-dev libboost-dev libboost-serialization-dev libssl-dev) ;;
    --orbslam3-check) packages+=(libgl1-mesa-dev libglew-dev libegl-dev libboost-dev) ;;
    *) echo "install-deps: unknown option '$option' (--orbslam2, --orbslam3, --orbslam3-check)" >&2; exit 2 ;;
  esac
done

sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi

# The parser tests and fuzz targets run under a comma-decimal locale (de_DE.UTF-8) to show that the
# number parsing ignores the locale; they skip loudly without it.
ensure_comma_locale() {
  if locale -a 2>/dev/null | grep -qiE '^de_DE\.utf-?8$'; then return 0; fi
  [[ -f /etc/locale.gen ]] && command -v locale-gen >/dev/null || return 0
  echo "install-deps: generating the de_DE.UTF-8 locale"
  grep -q '^de_DE.UTF-8 UTF-8' /etc/locale.gen || echo 'de_DE.UTF-8 UTF-8' | "${sudo_cmd[@]}" tee -a /etc/locale.gen >/dev/null
  "${sudo_cmd[@]}" locale-gen >/dev/null
}

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  ensure_comma_locale
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
ensure_comma_locale
