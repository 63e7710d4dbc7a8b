#!/usr/bin/env bash
# Fluid solver benchmarks for doc/benchmarks.md:
#  1. preconditioner robustness: outer FGMRES iterations over mesh levels,
#     time steps, drag and a jumping fluid fraction (2D levels 3..7, 3D 2..4),
#     with the drag integrated at quadrature points (default) and with its
#     cell means (`Drag coefficient averaging = cell`); LARGE=1 adds 3D
#     level 5 (several GiB; the default without the 1e8 cells, which do not
#     converge and would take hours); INNER=1 the inner-GMRES variant;
#  2. what switching physics off saves: the same scene solved as
#     Navier-Stokes/BDF2, Stokes/BDF2 and steady Stokes.
# Usage: benchmarks/run_fluid_benchmarks.sh [OUTDIR]  (after scripts/setup.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/environment.sh
out=${1:-benchmarks/results}
mkdir -p "$out"
cmake --build build --target benchmarks -j"$(nproc)" >/dev/null

bin=build/benchmarks/fluid_preconditioner
$bin 2 3 7 > "$out/preconditioner_2d.md"
$bin 3 2 4 > "$out/preconditioner_3d.md"
FLUID_BENCH_DRAG_AVERAGING=cell $bin 2 3 7 > "$out/preconditioner_2d_cell.md"
FLUID_BENCH_DRAG_AVERAGING=cell $bin 3 2 4 > "$out/preconditioner_3d_cell.md"
if [ "${LARGE:-0}" = 1 ]; then
  FLUID_BENCH_BETA=0,1,1e4 $bin 3 5 5 > "$out/preconditioner_3d_level5.md"
  FLUID_BENCH_DRAG_AVERAGING=cell $bin 3 5 5 \
    > "$out/preconditioner_3d_level5_cell.md"
fi
# INNER=1: the drag-jump columns with the inner GMRES on the velocity block
# (doc/benchmarks.md, "The drag-jump cells").
if [ "${INNER:-0}" = 1 ]; then
  FLUID_BENCH_DT=1,steady FLUID_BENCH_BETA=1e4,1e8 \
    $bin 2 3 7 stokes Cahouet-Chabard 1 \
    "Velocity inner iterations = 15; Max iterations = 300" \
    > "$out/preconditioner_2d_inner.md"
fi

# Physics switched off: the porous channel scene, 10 steps each.
{
  echo "| model | steps | fluid iterations (sum) | wall time s |"
  echo "|---|---|---|---|"
  for model in "Navier-Stokes BDF2:true:true" "Stokes BDF2:false:true" "steady Stokes:false:false"; do
    IFS=: read -r name advection transient <<<"$model"
    scene="$out/channel_${advection}_${transient}.prm"
    sed -e "s/set Advection = true/set Advection = $advection/" \
        -e "/set Advection/a\\  set Time derivative = $transient" \
        -e "s#^set Dimension = 2#set Dimension = 2\nset Output directory = $out/channel_${advection}_${transient}#" \
        prm/porous_channel.prm > "$scene"
    build/immersed-grains "$scene" >/dev/null
    stats="$out/channel_${advection}_${transient}/statistics.csv"
    python3 - "$name" "$stats" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[2])))
its = sum(int(float(r["fluid_iterations"])) for r in rows)
print(f"| {sys.argv[1]} | {len(rows) - 1} | {its} | {float(rows[-1]['wall_time']):.2f} |")
PY
  done
} > "$out/physics_switch.md"
cat "$out"/*.md
