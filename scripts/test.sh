#!/usr/bin/env bash
# Installs, builds and runs the whole test suite (GoogleTest under ctest).
# With --sanitize, builds in build-asan/ with AddressSanitizer and UndefinedBehaviorSanitizer.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
if [ "${1:-}" = "--sanitize" ]; then
  export BPM_BUILD_DIR="$root/build-asan"
  "$root/scripts/build.sh" -DBPM_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBPM_BUILD_BENCH=OFF
else
  "$root/scripts/build.sh"
fi
build="${BPM_BUILD_DIR:-$root/build}"
cd "$build"
ctest --output-on-failure -j 2
