#!/usr/bin/env bash
# Fuzzes every reader: builds build-fuzz (clang, libFuzzer + ASan + UBSan; SCFLOAM_FUZZ_BUILD
# names another tree) and runs each fuzz/<name>_fuzz target for SECONDS_PER_TARGET seconds
# (default 10), one target per core at a time.
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]
#
# Two uses:
# - CI (scripts/test.sh sets SCFLOAM_FUZZ_SEED=1 and SCFLOAM_FUZZ_BUILD=build-asan): reproducible.
#   libFuzzer runs with -seed=N and starts from a fresh corpus holding only the seeds
#   (<tree>/fuzz-corpus-seed/<name>/, emptied first), so what it tries depends on the sources,
#   the build tree's flags, ../shared and N alone: a failed CI run is re-run with the command
#   the summary prints (given at least as many seconds).
# - Bench (`bash scripts/fuzz.sh 300`, no SCFLOAM_FUZZ_SEED): libFuzzer picks the seed (printed
#   in the summary) and the corpus keeps growing in <tree>/fuzz-corpus/<name>/ between runs.
#   Results: docs/robustness.md.
# Seeds: fuzz/corpus/<name>/ plus samples cut at run time from ../shared/data and config/.
# Before fuzzing, every saved crash input (tests/io/fuzz_regressions/<name>/) is replayed once.
# A crash leaves its input in <tree>/fuzz-crashes/<name>/ and makes this script fail:
# fix the reader and copy the input to tests/io/fuzz_regressions/<name>/ (replayed by test_io).
set -euo pipefail
seconds="${1:-10}"
shift || true
cd "$(dirname "$0")/.."
shared="${SCFLOAM_SHARED_DIR:-$(cd .. && pwd)/shared}"
build="${SCFLOAM_FUZZ_BUILD:-build-fuzz}"
seed="${SCFLOAM_FUZZ_SEED:-}"
# The harness writes each input to a file in the temporary folder: a folder of its own, removed
# at exit, so that runs leave nothing in /tmp.
TMPDIR="$(mktemp -d "${TMPDIR:-/tmp}/scfloam-fuzz.XXXXXX")"
export TMPDIR
trap 'rm -rf "$TMPDIR"' EXIT

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for f in fuzz/*_fuzz.cpp; do targets+=("$(basename "$f" _fuzz.cpp)"); done
fi

# A tree already configured for fuzzing (scripts/test.sh's build-asan, which also holds the
# sanitizer tests) is used as it is; otherwise a fuzz-only tree is configured.
if ! grep -q '^SCFLOAM_FUZZ:BOOL=ON' "$build/CMakeCache.txt" 2>/dev/null ||
   { [ ! -f "$build/Makefile" ] && [ ! -f "$build/build.ninja" ]; }; then
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DSCFLOAM_FUZZ=ON -DSCFLOAM_BUILD_TESTS=OFF -DSCFLOAM_BUILD_BENCH=OFF \
    -DSCFLOAM_SHARED_DIR="$shared" >"$build.configure.log" 2>&1 ||
    { cat "$build.configure.log"; exit 1; }
fi
cmake --build "$build" -j"$(nproc)" --target "${targets[@]/%/_fuzz}"

# Real files (cut to a few KB, or the smallest bags), so that the fuzzer starts from inputs
# the readers accept. Nothing is copied into the repository (licences: fuzz/corpus/README.md).
seed_from_shared() {
  local name="$1" out="$2" data="$shared/data" f i=0
  [ -d "$data" ] || return 0
  case "$name" in
    kitti_bin)
      for f in "$data"/kitti/scans/*/velodyne/000000.bin; do
        [ -f "$f" ] || continue
        head -c 1024 "$f" >"$out/seed-bin-$i-1k"; head -c 4096 "$f" >"$out/seed-bin-$i-4k"; i=$((i + 1))
      done ;;
    kitti_calib)
      for f in "$data"/kitti/scans/*/calib.txt; do
        [ -f "$f" ] && cp "$f" "$out/seed-calib-$i" && i=$((i + 1))
      done ;;
    trajectory)
      for f in "$data"/kitti/scans/*/poses.txt "$data"/kitti/scans/*/times.txt; do
        [ -f "$f" ] && head -n 5 "$f" >"$out/seed-traj-$i" && i=$((i + 1))
      done ;;
    config)
      for f in config/*.yaml; do cp "$f" "$out/seed-$(basename "$f")"; done ;;
    ros1_bag)
      for f in cdcpd/rope_example_10_points_2020-02-20-16-58-46.bag \
               cdcpd/rope_example_11_points_2020-02-26-10-26-45.bag \
               rosbag.js/fixtures/no-messages.bag rosbag.js/fixtures/example-unsorted-chunks.bag; do
        [ -f "$data/bags/$f" ] && cp "$data/bags/$f" "$out/seed-$(basename "$f")"
      done ;;
    ros2_sqlite)
      for f in ros2-rosbag2/rosbag2_tests/resources/sqlite3/cdr_test/cdr_test_0.db3 \
               ros2-rosbag2/ros2bag/test/resources/empty_bag/empty_bag_0.db3 \
               ros2-rosbag2/rosbag2_py/test/resources/sqlite3/talker/talker.db3; do
        [ -f "$data/bags/$f" ] && cp "$data/bags/$f" "$out/seed-$(basename "$f")"
      done ;;
    mcap)
      for f in ros2-rosbag2/rosbag2_transport/test/resources/mcap/test_bag_for_seek/test_bag_for_seek_0.mcap \
               ros2-rosbag2/rosbag2_tests/resources/mcap/cdr_test/cdr_test_0.mcap; do
        [ -f "$data/bags/$f" ] && cp "$data/bags/$f" "$out/seed-$(basename "$f")"
      done
      # The MCAP conformance variants of one message (chunked, compressed, indexed, padded...).
      find "$data/bags/foxglove-mcap/tests/conformance/data/OneMessage" -name '*.mcap' 2>/dev/null |
        while read -r f; do cp "$f" "$out/seed-$(basename "$f")"; done ;;
  esac
}

summary="$build/fuzz-summary.txt"
limits=(-timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048)
# fuzz_one NAME: replays NAME's saved crashes, fuzzes it, and writes its summary line to
# $build/fuzz-NAME.row; returns non-zero on a finding. One fuzzer per core at a time: each
# runs on one thread, so the targets share the machine without changing what any one tries.
fuzz_one() {
  local name="$1"
  local fuzzer="$build/bin/${name}_fuzz" crashes="$build/fuzz-crashes/$name" log="$build/fuzz-$name.log"
  local row="$build/fuzz-$name.row" corpus result max_len execs cov ft used_seed
  local -a regressions seed_args seeds
  mkdir -p "$crashes"
  # -timeout: an input taking longer than 10 s is a hang; -rss_limit_mb / -malloc_limit_mb: a
  # 4 GB size field that allocates is a finding, not an out-of-memory of the machine.
  regressions=(tests/io/fuzz_regressions/"$name"/*)
  if [ -e "${regressions[0]}" ] &&
     ! "$fuzzer" "${limits[@]}" "${regressions[@]}" >"$build/fuzz-$name-regressions.log" 2>&1; then
    printf "%-14s %8s %10s %10s %7s %7s %8s %11s  %s\n" "$name" 0 "${#regressions[@]}" - - - - - \
      "REGRESSION (see $build/fuzz-$name-regressions.log)" >"$row"
    return 1
  fi
  if [ -n "$seed" ]; then
    corpus="$build/fuzz-corpus-seed/$name"
    rm -rf "$corpus"
    seed_args=(-seed="$seed")
  else
    corpus="$build/fuzz-corpus/$name"
    seed_args=()
  fi
  mkdir -p "$corpus"
  seed_from_shared "$name" "$corpus"
  seeds=()
  [ -d "fuzz/corpus/$name" ] && seeds+=("fuzz/corpus/$name")
  echo "fuzz: $name for ${seconds}s${seed:+ (seed $seed)}"
  result=ok
  max_len=16384
  case "$name" in ros1_bag | ros2_sqlite | mcap) max_len=65536 ;; esac
  if ! "$fuzzer" "${seed_args[@]}" -max_total_time="$seconds" "${limits[@]}" \
      -max_len="$max_len" -print_final_stats=1 -artifact_prefix="$crashes/" \
      "$corpus" "${seeds[@]}" >"$log" 2>&1; then
    result="CRASH (see $log and $crashes/)"
    grep -E "ERROR|SUMMARY|Test unit written" "$log" | head -n 8 || true
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -n 1 | cut -d' ' -f2)
  ft=$(grep -oE 'ft: [0-9]+' "$log" | tail -n 1 | cut -d' ' -f2)
  used_seed=$(sed -n 's/^INFO: Seed: *//p' "$log" | head -n 1)
  printf "%-14s %8s %10s %10s %7s %7s %8s %11s  %s\n" "$name" "$seconds" "${execs:-?}" \
    "$(( ${execs:-0} / (seconds > 0 ? seconds : 1) ))" "${cov:-?}" "${ft:-?}" \
    "$(ls "$corpus" | wc -l)" "${used_seed:-?}" "$result" >"$row"
  [ "$result" = ok ]
}

failed=0
running=0
for name in "${targets[@]}"; do
  rm -f "$build/fuzz-$name.row"
  if [ "$running" -ge "$(nproc)" ]; then
    wait -n || failed=1
    running=$((running - 1))
  fi
  fuzz_one "$name" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || failed=1
  running=$((running - 1))
done
printf "%-14s %8s %10s %10s %7s %7s %8s %11s  %s\n" target seconds execs execs/s cov ft corpus seed result >"$summary"
for name in "${targets[@]}"; do
  if [ -f "$build/fuzz-$name.row" ]; then cat "$build/fuzz-$name.row" >>"$summary"
  else printf "%-14s %s\n" "$name" "NO RESULT (the harness itself failed)" >>"$summary"; failed=1; fi
done
cat "$summary"
if [ "$failed" = 1 ] && [ -n "$seed" ]; then
  echo "fuzz: to re-run this exactly: SCFLOAM_FUZZ_BUILD=$build SCFLOAM_FUZZ_SEED=$seed bash scripts/fuzz.sh $seconds ${targets[*]}"
fi
exit $failed
