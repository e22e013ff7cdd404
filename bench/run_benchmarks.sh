#!/usr/bin/env bash
# Produces docs/benchmarks.md: micro-benchmarks (Google Benchmark, medians of repetitions),
# simulator speed, and whole runs of the three modes on simulated sequences (medians of REPEAT
# runs). Run it on a quiet machine; it says how many cores it saw.
#   bash bench/run_benchmarks.sh                 # default set
#   REPEAT=5 SEQUENCES="city-loops kitti05" bash bench/run_benchmarks.sh
#   SEQUENCES="city-loops-short kitti05 kitti00:1"   # NAME:N runs that sequence N times instead
set -euo pipefail
cd "$(dirname "$0")/.."
repeat="${REPEAT:-3}"
sequences="${SEQUENCES:-city-loops}"
modes="${MODES:-odometry simple-sc optimized}"
results="bench-results"
mkdir -p "$results" data/bench
bash scripts/install-deps.sh
bash scripts/build.sh > "$results/build.log"
bin=build/bin
shared="${SCFLOAM_SHARED_DIR:-$(cd .. && pwd)/shared}"

echo "== micro-benchmarks"
for b in bench_odometry bench_loop bench_pose_graph bench_readers; do
  SCFLOAM_SHARED_DIR="$shared" "$bin/$b" --benchmark_repetitions="$repeat" \
    --benchmark_report_aggregates_only=true --benchmark_format=json > "$results/$b.json"
done

# name -> simulate arguments
sim_args() {
  case "$1" in
    city-loops) echo "--frames 2400 --seed 11 --route loops" ;;
    city-loops-short) echo "--frames 1000 --seed 1 --route loops" ;;
    kitti00) echo "--replay $shared/data/kitti/ground-truth/poses/00.txt --seed 2" ;;
    kitti05) echo "--replay $shared/data/kitti/ground-truth/poses/05.txt --seed 3" ;;
    # A VLP-16 city loop: sparse rings make the odometry drift about as much as F-LOAM does on
    # real KITTI (0.8 %), the regime of the paper's Table I (docs/loop_closure.md, session 11).
    vlp16-loops) echo "--sensor vlp16 --frames 1500 --seed 5 --route loops" ;;
    *) echo "unknown sequence $1" >&2; exit 1 ;;
  esac
}

# name -> extra `scfloam run` arguments (the sensor's preset)
run_args() {
  case "$1" in
    vlp16-loops) echo "--sensor vlp16" ;;
    *) echo "" ;;
  esac
}

for entry in $sequences; do
  seq="${entry%%:*}"
  runs="$repeat"
  [ "$entry" != "$seq" ] && runs="${entry#*:}"
  dir="data/bench/$seq"
  if [ ! -f "$dir/poses.txt" ]; then
    echo "== simulating $seq"
    start=$(date +%s%N)
    # shellcheck disable=SC2046
    "$bin/scfloam" simulate --out "$dir" $(sim_args "$seq") --force
    end=$(date +%s%N)
    frames=$(ls "$dir/velodyne" | wc -l)
    echo "{\"sequence\": \"$seq\", \"frames\": $frames, \"ms\": $(( (end - start) / 1000000 ))}" > "$results/sim-$seq.json"
  fi
  for mode in $modes; do
    rm -rf "$results"/run-"$seq"-"$mode"-*
    for r in $(seq 1 "$runs"); do
      echo "== $seq $mode run $r/$runs"
      # shellcheck disable=SC2046
      "$bin/scfloam" run "$dir" $(run_args "$seq") --mode "$mode" --out "$results/run-$seq-$mode-$r" --force --quiet > /dev/null
    done
  done
done

/usr/bin/python3 bench/make_benchmarks_md.py "$results" docs/benchmarks.md "$repeat" "$sequences" "$modes"
echo "wrote docs/benchmarks.md"
