#!/usr/bin/env python3
"""Checks that includes in src/ point one way (docs/ARCHITECTURE.md): a header may include only
headers of its own layer or below; lights, materials and camera include none of each other, nor do
the integrators; integrator/ does not include photons/. Prints each violation; exits 1 if any."""
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")


def layer(path):
    folder, name = path.split("/")[0], path.split("/")[-1]
    if folder == "base":
        return 0
    if folder in ("textures", "film"):
        return 1
    if folder == "scene":
        return 3 if name.startswith(("render_scene", "accel", "flatten")) else 1
    if folder in ("lights", "materials", "camera"):
        return 2
    if folder in ("integrator", "photons"):
        return 4
    if folder in ("path", "bpm", "fpm"):
        return 5
    if folder == "render":
        return 6
    raise SystemExit(f"check-layers: src/{path} is in no layer; add its folder to scripts/check-layers.py")


def main():
    bad = []
    for folder, _, files in os.walk(ROOT):
        for name in files:
            rel = os.path.relpath(os.path.join(folder, name), ROOT)
            if "_test" in name or not name.endswith((".h", ".cpp")):
                continue
            own = layer(rel)
            text = open(os.path.join(ROOT, rel), encoding="utf-8").read()
            for inc in re.findall(r'#include "([^"]+)"', text):
                if not os.path.exists(os.path.join(ROOT, inc)):
                    continue
                other = layer(inc)
                same_folder = inc.split("/")[0] == rel.split("/")[0]
                sideways = other == own and not same_folder and own in (2, 5)
                upward = other > own or (rel.startswith("integrator/") and inc.startswith("photons/"))
                if upward or sideways:
                    bad.append(f"src/{rel} includes {inc}")
    for b in sorted(bad):
        print("check-layers:", b)
    print(f"check-layers: {len(bad)} include(s) against the layering")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
