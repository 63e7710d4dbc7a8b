#!/usr/bin/env bash
# Set-up (scripts/setup.sh) and the whole test suite (ctest, Release).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/environment.sh
cd build
# Each .cc test's executable is shared by its serial and mpirun=N variants;
# built first, so that two variants running side by side do not both build
# (and race on) it.
targets=$(make help | sed -n 's/^\.\.\. \(tests\.[A-Za-z0-9_]*\.release\)$/\1/p')
[ -z "$targets" ] || cmake --build . -j"$IMMERSED_GRAINS_JOBS" --target $targets
ctest -j"$IMMERSED_GRAINS_JOBS" --output-on-failure --timeout 1500 "$@"
