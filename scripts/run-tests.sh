#!/usr/bin/env bash
# Set-up (scripts/setup.sh) and the whole test suite (ctest, Release).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/environment.sh
cd build
ctest -j"$(nproc)" --output-on-failure --timeout 1500 "$@"
