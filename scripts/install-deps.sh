#!/usr/bin/env bash
# Installs dyncull's build, test and benchmark dependencies from Debian 12 packages.
# Idempotent: installs only what is missing, so CI and repeated runs cost a few seconds.
set -euo pipefail

packages=(g++ clang cmake make pkg-config libeigen3-dev libopencv-dev libceres-dev
          libgtest-dev libgmock-dev libbenchmark-dev libnanoflann-dev)
# Open3D is an optional benchmark peer (ICP); set DYNCULL_WITH_OPEN3D=1 to install it.
if [[ "${DYNCULL_WITH_OPEN3D:-0}" == 1 ]]; then packages+=(libopen3d-dev); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
echo "install-deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
