#!/usr/bin/env bash
# Configures and builds scfloam (Release) into build/ (or $SCFLOAM_BUILD_DIR); extra arguments
# go to cmake's configure.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${SCFLOAM_BUILD_DIR:-build}"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release "$@" > "$build-configure.log" 2>&1 || { cat "$build-configure.log"; exit 1; }
cmake --build "$build" -j"$(nproc)"
