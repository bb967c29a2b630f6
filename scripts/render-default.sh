#!/usr/bin/env bash
# Installs, builds and renders the bundled Cornell box with backward photon mapping to
# out/cornell-box.{exr,png,luminance.png,error.png,bias.png,json}; after it, `python3` imports the
# Python module `bpm` (scripts/install-python.sh).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh"
"$root/scripts/install-python.sh"
mkdir -p "$root/out"
"$root/build/bpm" render "$root/scenes/cornell-box.pbrt" --integrator bpm -o "$root/out/cornell-box.exr" "$@"
echo "wrote $root/out/cornell-box.exr and cornell-box.png"
