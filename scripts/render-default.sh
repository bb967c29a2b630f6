#!/usr/bin/env bash
# Installs, builds and renders the bundled Cornell box with backward photon mapping to
# out/cornell-box.{exr,png,luminance.png,error.png,bias.png,json}.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh"
mkdir -p "$root/out"
"$root/build/bpm" render "$root/scenes/cornell-box.pbrt" --integrator bpm -o "$root/out/cornell-box.exr" "$@"
echo "wrote $root/out/cornell-box.exr and cornell-box.png"
