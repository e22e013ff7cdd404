#!/bin/bash
# Long run (issue 8): one simulated patrol lap (~1030 frames, ~2 GB) replayed lap after lap
# through the whole pipeline for FRAMES frames (default 20 000: a robot patrolling for 33
# minutes), at low priority (NICE, default 10). Records RSS every 2 s and every frame's odometry
# time, then plots docs/long_run.png and writes OUT/table.md (for docs/robustness-long-run.md).
# EXTRA passes long_run options, e.g. EXTRA="--resident-keyframes 500" (pipeline.* keys).
#   BUILD=build-longrun FRAMES=20000 MODE=optimized bash bench/long_run.sh
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${BUILD:-$ROOT/build}
FRAMES=${FRAMES:-20000}
MODE=${MODE:-optimized}
NICE=${NICE:-10}
EXTRA=${EXTRA:-}
WORK=${WORK:-$BUILD/long-run}
cmake --build "$BUILD" --target scfloam_cli long_run -j2
if [ ! -f "$WORK/lap/poses.txt" ]; then
  nice -n "$NICE" "$BUILD/bin/scfloam" simulate --scenario patrol --seed 1 --out "$WORK/lap" --force --quiet
fi
# shellcheck disable=SC2086
nice -n "$NICE" "$BUILD/bin/long_run" "$WORK/lap" "$WORK/out" --frames "$FRAMES" --mode "$MODE" --sample-s 2 $EXTRA
/usr/bin/python3 "$ROOT/bench/long_run_plot.py" "$WORK/out" "$ROOT/docs/long_run.png" "$WORK/out/table.md"
