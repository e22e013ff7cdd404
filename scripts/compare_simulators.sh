#!/usr/bin/env bash
# A seed must give the same simulated sequence on every compiler. Runs sim_digest (worlds,
# trajectories, traffic plans and three short sequences, hashed; tests/support/sim_digest.cpp)
# from two build trees and fails if they differ. scripts/test.sh runs it on the gcc build and
# the clang sanitizer build.
# Usage: scripts/compare_simulators.sh BUILD_A BUILD_B [SHARED_DIR]
set -euo pipefail
a="$1" b="$2"
args=("${@:3}")
out_a="$a/sim-digest.txt" out_b="$b/sim-digest.txt"
"$a/bin/sim_digest" "${args[@]}" >"$out_a"
"$b/bin/sim_digest" "${args[@]}" >"$out_b"
if ! diff "$out_a" "$out_b"; then
  echo "error: $a and $b simulate different sequences for the same seed (above: < $a, > $b)" >&2
  exit 1
fi
echo "sim_digest: $(wc -l <"$out_a") configurations identical in $a and $b"
