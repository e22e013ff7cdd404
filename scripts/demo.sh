#!/usr/bin/env bash
# The main job on a built-in default: install, build, simulate a city sequence with loops,
# run scfloam on it and print accuracy against the ground truth and speed.
#   FRAMES=1500 SEED=7 bash scripts/demo.sh    # a longer drive in another world
set -euo pipefail
cd "$(dirname "$0")/.."
frames="${FRAMES:-1000}"
seed="${SEED:-1}"
mode="${MODE:-}"
bash scripts/install-deps.sh
bash scripts/build.sh
seq="data/demo-seed${seed}-${frames}"
if [ ! -f "$seq/poses.txt" ]; then
  echo "== simulating a city drive with loops: $frames frames, seed $seed -> $seq"
  build/bin/scfloam simulate --out "$seq" --frames "$frames" --seed "$seed" --route loops --force
fi
echo "== running scfloam on $seq"
build/bin/scfloam run "$seq" --out "out/demo-seed${seed}-${frames}" --force ${mode:+--mode "$mode"}
