#!/bin/bash
# Long run (issue 8): one simulated patrol lap (~1030 frames, ~2 GB) replayed lap after lap
# through the whole pipeline for FRAMES frames (default 20 000: a robot patrolling for 33
# minutes), at low priority. Records RSS every 2 s and every frame's odometry time, then
# plots docs/long_run.png and writes OUT/table.md (for docs/robustness-long-run.md).
#   BUILD=build-scenes FRAMES=20000 MODE=optimized bash bench/long_run.sh
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${BUILD:-$ROOT/build}
FRAMES=${FRAMES:-20000}
MODE=${MODE:-optimized}
WORK=${WORK:-$BUILD/long-run}
cmake --build "$BUILD" --target scfloam_cli long_run -j2
if [ ! -f "$WORK/lap/poses.txt" ]; then
  nice -n 10 "$BUILD/bin/scfloam" simulate --scenario patrol --seed 1 --out "$WORK/lap" --force --quiet
fi
nice -n 10 "$BUILD/bin/long_run" "$WORK/lap" "$WORK/out" --frames "$FRAMES" --mode "$MODE" --sample-s 2
/usr/bin/python3 "$ROOT/bench/long_run_plot.py" "$WORK/out" "$ROOT/docs/long_run.png" "$WORK/out/table.md"
