#!/usr/bin/env bash
# Installs what is needed, builds, and runs the whole test suite (GoogleTest through ctest).
# Real-data tests read ../shared/ (override with SCFLOAM_SHARED_DIR=...); without it they skip.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
shared="${SCFLOAM_SHARED_DIR:-$(cd .. && pwd)/shared}"
bash scripts/build.sh -DSCFLOAM_SHARED_DIR="$shared"
cd build
ctest --output-on-failure -j"$(nproc)" --timeout 900
