#!/usr/bin/env bash
# Installs what is needed, builds, and runs the whole test suite (GoogleTest through ctest);
# then the same unit tests under AddressSanitizer + UndefinedBehaviorSanitizer (build-asan)
# and a short fuzz of every reader (scripts/fuzz.sh 10). docs/robustness.md has the figures.
# Real-data tests read ../shared/ (override with SCFLOAM_SHARED_DIR=...); without it they skip.
# SCFLOAM_SKIP_SANITIZERS=1 runs the plain suite only (a quick local check).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
shared="${SCFLOAM_SHARED_DIR:-$(cd .. && pwd)/shared}"
bash scripts/build.sh -DSCFLOAM_SHARED_DIR="$shared"
(cd build && ctest --output-on-failure -j"$(nproc)" --timeout 900)
[ "${SCFLOAM_SKIP_SANITIZERS:-0}" = 1 ] && exit 0

# ASan + UBSan: any finding aborts its test. Benchmarks are not built there.
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSCFLOAM_SANITIZE=ON \
  -DSCFLOAM_BUILD_BENCH=OFF -DSCFLOAM_SHARED_DIR="$shared" >build-asan.configure.log 2>&1 ||
  { cat build-asan.configure.log; exit 1; }
cmake --build build-asan -j"$(nproc)"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
(cd build-asan && ctest --output-on-failure -j"$(nproc)" --timeout 1800)

bash scripts/fuzz.sh 10
