#!/usr/bin/env bash
# Configures and builds bpm (Release) in build/, installing dependencies first if needed.
# BPM_BUILD_DIR and extra CMake arguments (e.g. -DBPM_SANITIZE=ON) may be given.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${BPM_BUILD_DIR:-$root/build}"
"$root/scripts/install-deps.sh"
if [ ! -f "$build/build.ninja" ]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
elif [ $# -gt 0 ]; then
  cmake -S "$root" -B "$build" "$@" >/dev/null
fi
ninja -C "$build" ${BPM_JOBS:+-j "$BPM_JOBS"}
