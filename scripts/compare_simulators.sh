#!/usr/bin/env bash
# A seed must give the same simulated sequence on every compiler. Runs sim_digest (worlds,
# trajectories, traffic plans and three short sequences, hashed; tests/support/sim_digest.cpp)
# from two build trees and fails if they differ. scripts/test.sh runs it on the gcc build and
# the clang sanitizer build.
# Usage: scripts/compare_simulators.sh BUILD_A BUILD_B [SHARED_DIR]
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 BUILD_A BUILD_B [SHARED_DIR]" >&2
  exit 2
fi
a="$1" b="$2"
# The trees' compilers, as CMake identified them: the same one twice would compare nothing.
compiler() {
  sed -n 's/^set(CMAKE_CXX_COMPILER_ID "\(.*\)")$/\1/p' "$1"/CMakeFiles/*/CMakeCXXCompiler.cmake | head -n 1
}
cc_a="$(compiler "$a")" cc_b="$(compiler "$b")"
if [ -z "$cc_a" ] || [ "$cc_a" = "$cc_b" ]; then
  echo "error: $a and $b must be built by two different compilers (found '${cc_a:-?}' and '${cc_b:-?}')" >&2
  exit 1
fi
out_a="$a/sim-digest.txt" out_b="$b/sim-digest.txt"
"$a/bin/sim_digest" "${@:3}" >"$out_a"
"$b/bin/sim_digest" "${@:3}" >"$out_b"
if ! diff "$out_a" "$out_b"; then
  echo "error: $a ($cc_a) and $b ($cc_b) simulate different sequences for the same seed (above: < $a, > $b)" >&2
  exit 1
fi
echo "sim_digest: $(wc -l <"$out_a") configurations identical under $cc_a ($a) and $cc_b ($b)"
