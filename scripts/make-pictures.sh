#!/usr/bin/env bash
# Remakes the pictures of README.md and docs/ from the bundled scenes (builds first if needed;
# a few minutes on 2 cores). Each picture is a fixed number of iterations with a fixed seed, so
# the same build remakes the same picture on any machine and thread count. The commands are the
# ones README.md and docs/MEASUREMENTS.md print under the pictures. BPM=PATH uses that program
# instead of building build/bpm.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bpm="${BPM:-}"
if [ -z "$bpm" ]; then
  "$root/scripts/build.sh"
  bpm="$root/build/bpm"
fi
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cd "$root"

# picture NAME [render arguments]: renders to a scratch folder, keeps docs/NAME.png.
picture() {
  local name="$1"
  shift
  "$bpm" render "$@" -q -o "$tmp/$name.exr"
  cp "$tmp/$name.png" "docs/$name.png"
  echo "make-pictures: docs/$name.png: bpm render $*"
}

picture caustic-sphere-bpm scenes/caustic-sphere.pbrt --integrator bpm --iterations 600 --seed 1
picture water-box-bpm scenes/water-box.pbrt --integrator bpm --iterations 400 --seed 1
picture light-guides-inside-bpm scenes/light-guides-inside.pbrt --integrator bpm --iterations 150 --seed 1
picture cornell-box-bpm scenes/cornell-box.pbrt --integrator bpm --iterations 300 --seed 1
picture room2-bpm scenes/room2.pbrt --integrator bpm --iterations 300 --seed 1
# The bias estimate of fixed, large radii: OUT.bias.png.
"$bpm" render scenes/caustic-sphere.pbrt --integrator bpm --iterations 256 --radius-policy fixed \
  --k0 4 --k1 4 --seed 1 -q -o "$tmp/bias.exr"
cp "$tmp/bias.bias.png" docs/caustic-sphere-bias.png
echo "make-pictures: docs/caustic-sphere-bias.png: the .bias.png of bpm render" \
  "scenes/caustic-sphere.pbrt --integrator bpm --iterations 256 --radius-policy fixed --k0 4 --k1 4 --seed 1"
# The false-colour luminance and the work plane's illuminance of the office: OUT.luminance.png and
# OUT.sensors.png.
"$bpm" render scenes/office-downlight.pbrt --sensors scenes/office-downlight-sensors.txt \
  --iterations 200 --seed 1 -q -o "$tmp/office.exr"
cp "$tmp/office.luminance.png" docs/office-downlight-luminance.png
cp "$tmp/office.sensors.png" docs/office-downlight-sensors.png
echo "make-pictures: docs/office-downlight-luminance.png, docs/office-downlight-sensors.png: the" \
  ".luminance.png and .sensors.png of bpm render scenes/office-downlight.pbrt --sensors" \
  "scenes/office-downlight-sensors.txt --iterations 200 --seed 1"
