#!/usr/bin/env bash
# Installs what is needed, builds, and runs the whole test suite (GoogleTest through ctest);
# then, from one clang tree (build-asan), the unit tests under AddressSanitizer +
# UndefinedBehaviorSanitizer (the end-to-end suites labelled `long` run in the plain build
# only, see cmake/modules.cmake), a check that gcc and clang simulate the same sequences, and
# a short, reproducible fuzz of every reader (SCFLOAM_FUZZ_SEED=1 scripts/fuzz.sh 10).
# Real-data tests read ../shared/ (override with SCFLOAM_SHARED_DIR=...); without it they skip.
# SCFLOAM_SKIP_SANITIZERS=1 runs the plain suite only (a quick local check).
# SCFLOAM_BUILD_DIR / SCFLOAM_ASAN_BUILD_DIR name the two build trees (default build,
# build-asan). Each stage's wall and CPU time goes to
# <build>.ci-stages.log and is printed at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${SCFLOAM_BUILD_DIR:-build}"
asan="${SCFLOAM_ASAN_BUILD_DIR:-build-asan}"
export SCFLOAM_BUILD_DIR="$build"
shared="${SCFLOAM_SHARED_DIR:-$(cd .. && pwd)/shared}"
jobs="$(nproc)"

stages="$(pwd)/$build.ci-stages.log"
: >"$stages"
# stage NAME COMMAND...: runs the command, appending its wall and CPU seconds to $stages.
stage() {
  local name="$1"
  shift
  if [ -x /usr/bin/time ]; then
    /usr/bin/time -a -o "$stages" -f "$name: %e s wall, %U s user + %S s sys" "$@"
  else
    local t0=$SECONDS
    "$@"
    echo "$name: $((SECONDS - t0)) s wall" >>"$stages"
  fi
}

stage "install-deps" bash scripts/install-deps.sh
stage "build" bash scripts/build.sh -DSCFLOAM_SHARED_DIR="$shared"
stage "ctest" ctest --test-dir "$build" --output-on-failure -j"$jobs" --timeout 900
if [ "${SCFLOAM_SKIP_SANITIZERS:-0}" = 1 ]; then cat "$stages"; exit 0; fi

# One clang tree serves the sanitizer tests and the fuzzers: ASan + UBSan (any finding aborts
# its test; clang's UBSan also checks float-to-integer conversions, which gcc's does not) and
# libFuzzer's coverage instrumentation. -O1 with -g1 (function names and lines in reports, no
# variable info) builds far cheaper than -O2 -g; benchmarks are not built. A tree left by an
# older version of this script (gcc) is rebuilt from scratch.
if [ "$asan" != "$build" ] && [ -f "$asan/CMakeCache.txt" ] &&
   ! grep -q '^CMAKE_CXX_COMPILER:[A-Z]*=.*clang' "$asan/CMakeCache.txt"; then
  rm -rf "$asan"
fi
cmake -S . -B "$asan" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DSCFLOAM_SANITIZE=ON -DSCFLOAM_FUZZ=ON \
  -DSCFLOAM_BUILD_BENCH=OFF -DSCFLOAM_SHARED_DIR="$shared" \
  >"$asan.configure.log" 2>&1 || { cat "$asan.configure.log"; exit 1; }
stage "asan-build" cmake --build "$asan" -j"$jobs"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"

# A seed gives the same simulated sequence on every compiler (gcc here, clang there).
stage "sim-compilers" bash scripts/compare_simulators.sh "$build" "$asan" "$shared"
stage "asan-ctest" ctest --test-dir "$asan" --output-on-failure -j"$jobs" --timeout 1800 -LE long

# The fuzzers come from the same tree. A fixed seed: a CI failure is re-run with the command
# scripts/fuzz.sh prints.
stage "fuzz" env SCFLOAM_FUZZ_BUILD="$asan" SCFLOAM_FUZZ_SEED="${SCFLOAM_FUZZ_SEED:-1}" bash scripts/fuzz.sh 10
cat "$stages"
