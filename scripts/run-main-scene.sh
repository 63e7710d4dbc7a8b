#!/usr/bin/env bash
# Set-up (scripts/setup.sh) and the main scene, written to output/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/environment.sh
scene=${1:-prm/falling_cloud_2d.prm}
build/immersed-grains "$scene"
