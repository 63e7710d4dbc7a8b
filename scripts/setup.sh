#!/usr/bin/env bash
# Installs what a fresh Debian 12 machine lacks, configures and builds
# immersed-grains in Release mode into build/. Safe to run again: packages
# already present are not reinstalled and the build is incremental.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(libdeal.ii-dev numdiff ccache openmpi-bin cmake make g++ python3
          python3-numpy python3-matplotlib)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

source scripts/environment.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$IMMERSED_GRAINS_JOBS"
