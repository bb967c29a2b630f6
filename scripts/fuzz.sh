#!/usr/bin/env bash
# Builds the library, the program and the fuzz targets with clang in build-fuzz/ (ASan, UBSan and
# libFuzzer's coverage; no tests or benchmarks) and runs each fuzz target for SECONDS (default 30)
# from its seed corpus: the scene parser with flattening, the PLY reader, image textures through
# OpenImageIO, and the IES and EULUMDAT readers. Seeds come from scenes/ and fuzz/seeds/; what a
# run learns is kept in build-fuzz/corpus/. A finding (crash, sanitizer report, leak, hang over
# 10 s, more than 4 GiB) stops its target, leaves the input in build-fuzz/findings/ and makes the
# script fail.
# FUZZ_SEED fixes libFuzzer's random seed (CI uses 1); unset, each run draws its own.
#   scripts/fuzz.sh [SECONDS] [TARGET...]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-30}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(scene_fuzzer ply_fuzzer image_fuzzer photometric_fuzzer)
build="$root/build-fuzz"

"$root/scripts/install-deps.sh"
if [ ! -f "$build/build.ninja" ]; then
  CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DBPM_FUZZ=ON -DBPM_BUILD_TESTS=OFF -DBPM_BUILD_BENCH=OFF >/dev/null
fi
ninja -C "$build" ${BPM_JOBS:+-j "$BPM_JOBS"}

mkdir -p "$build/findings"
failed=0
for target in "${targets[@]}"; do
  corpus="$build/corpus/$target"
  mkdir -p "$corpus"
  seeds=("$root/fuzz/seeds/$target")
  if [ "$target" = scene_fuzzer ]; then seeds+=("$root/scenes"); fi
  if [ "$target" = image_fuzzer ]; then
    # An image seed is its extension's index (the target's first byte) followed by the file.
    mkdir -p "$build/image_seeds"
    printf '\x00' | cat - "$root/scenes/textures/wood.png" >"$build/image_seeds/wood.png.seed"
    seeds+=("$build/image_seeds")
  fi
  echo "fuzz: $target for ${seconds} s"
  run() {
    ASAN_OPTIONS="detect_leaks=$1" LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp" \
      "$build/$target" "$corpus" "${seeds[@]}" \
      -max_total_time="$seconds" -seed="${FUZZ_SEED:-0}" -timeout=10 -rss_limit_mb=4096 \
      -max_len=65536 -print_final_stats=1 -artifact_prefix="$build/findings/$target-" \
      2>"$build/$target.log"
  }
  ok=1
  run 1 || ok=0
  # LeakSanitizer needs ptrace; where the machine forbids it, the run goes on without leak checks.
  if [ $ok = 0 ] && grep -aq "LeakSanitizer has encountered a fatal error" "$build/$target.log"; then
    echo "fuzz: LeakSanitizer cannot run here; $target runs without leak detection" >&2
    ok=1
    run 0 || ok=0
  fi
  if [ $ok = 0 ]; then
    echo "fuzz: $target found a problem; see $build/$target.log and $build/findings/" >&2
    grep -av "^#\|NEW_FUNC" "$build/$target.log" | tail -n 40 >&2
    failed=1
  fi
  grep -aE "stat::number_of_executed_units|stat::peak_rss_mb" "$build/$target.log" | sed "s/^/  /"
done
exit $failed
