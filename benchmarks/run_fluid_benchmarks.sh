#!/usr/bin/env bash
# Fluid solver benchmarks for doc/benchmarks.md:
#  1. preconditioner robustness: outer FGMRES iterations over mesh levels,
#     time steps, drag and a jumping fluid fraction (2D levels 3..7, 3D 2..4),
#     with the default `Drag coefficient averaging = jump` (cell means in the
#     cells the jump cuts), with the drag at the quadrature points
#     (`quadrature`) and with the same physical drag on
#     every level (FIXED=1); LARGE=1 adds 3D level 5 (several GiB);
#     INNER=1 the inner-GMRES variant;
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
FLUID_BENCH_DRAG_AVERAGING=quadrature FLUID_BENCH_BETA=0,1,1e4 \
  $bin 2 3 7 > "$out/preconditioner_2d_quadrature.md"
if [ "${FIXED:-0}" = 1 ]; then
  FLUID_BENCH_BETA_FIXED=1 FLUID_BENCH_DT=steady,1 FLUID_BENCH_BETA=1e2,1e4,1e6 \
    $bin 2 3 7 > "$out/preconditioner_2d_fixed_beta.md"
fi
if [ "${LARGE:-0}" = 1 ]; then
  FLUID_BENCH_DT=1,steady,1e-4 $bin 3 5 5 > "$out/preconditioner_3d_level5.md"
fi
# GEOMETRY=1: the domains the constants were not fitted on (doc/adaptivity.md,
# "The fluid preconditioner on adaptive meshes"): an adaptive mesh around the
# ball (levels 2-6 in 2D, 1-4 in 3D), a column 1 x 8 (walled all round, and
# with periodic or slip sides) and a slab 8 x 1/8.
if [ "${GEOMETRY:-0}" = 1 ]; then
  export FLUID_BENCH_DT=1,steady FLUID_BENCH_BETA=0,1e4,1e8
  FLUID_BENCH_GEOMETRY=adaptive $bin 2 2 6 > "$out/preconditioner_2d_adaptive.md"
  FLUID_BENCH_GEOMETRY=adaptive $bin 3 1 4 > "$out/preconditioner_3d_adaptive.md"
  FLUID_BENCH_GEOMETRY=column $bin 2 3 5 > "$out/preconditioner_2d_column.md"
  FLUID_BENCH_GEOMETRY=slab $bin 2 3 5 > "$out/preconditioner_2d_slab.md"
  FLUID_BENCH_GEOMETRY=column $bin 3 1 2 > "$out/preconditioner_3d_column.md"
  FLUID_BENCH_GEOMETRY=slab $bin 3 1 2 > "$out/preconditioner_3d_slab.md"
  for sides in periodic_column slip_column; do
    FLUID_BENCH_GEOMETRY=$sides $bin 2 3 5 > "$out/preconditioner_2d_$sides.md"
    FLUID_BENCH_GEOMETRY=$sides $bin 3 1 2 > "$out/preconditioner_3d_$sides.md"
  done
  unset FLUID_BENCH_DT FLUID_BENCH_BETA
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
