#!/usr/bin/env python3
"""Would bpm's defaults have been chosen the same without a scene? A leave-one-out table.

For each default studied (k0, k1 and so on: CANDIDATES) every scene renders with bpm at each
candidate value for the same time (the other settings at their defaults), and is scored by relMSE
against the equal-time reference kept in equal_time_references/ (made by `build/equal_time`,
another seed). The value "chosen on all" minimises the geometric mean of the relMSE over all
scenes; the value "chosen without" a scene minimises it over the others. The table gives, per
scene, the relMSE with each and their ratio: how much the scene loses by having been left out of
the choice (1.00: nothing). Prints figures; never fails.

  PYTHONPATH=build/python /usr/bin/python3 bench/leave_one_out.py [--time S] [--seeds 1,2]
      [--scenes a,b] [--defaults k0,k1] [--values 4.5,6] [--json OUT.json]

Run from the project root, where equal_time_references/ is (make missing references with
`build/equal_time --references-only --scenes ...`)."""
import argparse
import glob
import json
import math
import os
import re

import numpy as np

import bpm

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
SCENES = {
    "caustic-sphere": "scenes/caustic-sphere.pbrt",
    "lamp-room": "scenes/lamp-room.pbrt",
    "shelf-room": "scenes/shelf-room.pbrt",
    "kitchen": "scenes/kitchen.pbrt",
    "fog": "scenes/fog.pbrt",
    "smoke": "scenes/smoke.pbrt",
    "spot-lens-fog": "scenes/spot-lens-fog.pbrt",
    "underwater": "scenes/underwater.pbrt",
    "volumetric-caustic": "../shared/scenes/volumetric-caustic/scene-v4.pbrt",
    "coffee": "../shared/scenes/coffee/scene-v4.pbrt",
    "killeroo-simple": "../shared/scenes/killeroo-simple/killeroo-simple.pbrt",
    "veach-mis": "../shared/scenes/veach-mis/scene-v4.pbrt",
    "staircase2": "../shared/scenes/staircase2/scene-v4-standin.pbrt",
    "spot-facets": "scenes/spot-facets.pbrt",
}
# Each default with its value and the values tried beside it (keyword arguments of bpm.render).
CANDIDATES = {
    "k0": (1.0, [0.7, 1.4]),
    "k1": (4.5, [2.0, 3.0, 6.0]),
    "emission_samples": (8, [4, 16]),
    "direct_samples": (8, [1, 2, 32]),
    "alpha": (2 / 3, [0.5, 0.8]),
}


def rel_mse(a, b):
    return float(np.mean((a - b) ** 2 / (b ** 2 + 0.01)))


def reference(name):
    found = glob.glob(os.path.join("equal_time_references", f"{name}_*.exr"))
    if not found:
        return None, None
    w, h = re.search(r"_(\d+)x(\d+)\.exr$", found[0]).groups()
    return bpm.read_exr(found[0]), (int(w), int(h))


def geo_mean(values):
    return math.exp(sum(math.log(v) for v in values) / len(values))


def choose(scores, values, scenes):
    """The value with the least geometric mean relMSE over `scenes`."""
    return min(values, key=lambda v: geo_mean([scores[s][v] for s in scenes]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--time", type=float, default=20)
    ap.add_argument("--seeds", default="1")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--defaults", default="k0,k1")
    ap.add_argument("--values", default="",
                    help="the values to try beside the default, for one default: 4.5,6")
    ap.add_argument("--json", default="")
    a = ap.parse_args()
    seeds = [int(s) for s in a.seeds.split(",")]
    scenes = []
    for name in a.scenes.split(","):
        ref, size = reference(name)
        path = os.path.join(ROOT, SCENES[name])
        if ref is None or not os.path.exists(path):
            print(f"# {name}: no reference or no scene here, left out")
            continue
        scenes.append((name, path, ref, size))
    results = {}
    for default in a.defaults.split(","):
        value, others = CANDIDATES[default]
        if a.values:
            others = [type(value)(v) for v in a.values.split(",")]
        values = [value] + others
        scores = {}
        for name, path, ref, size in scenes:
            scene = bpm.Scene(path)
            scores[name] = {}
            for v in values:
                errors = [rel_mse(scene.render(integrator="bpm", time=a.time, seed=seed,
                                               resolution=size, **{default: v}).image, ref)
                          for seed in seeds]
                scores[name][v] = geo_mean(errors)
                print(f"# {default}={v:g} {name}: relMSE {scores[name][v]:.3e}", flush=True)
        names = [s[0] for s in scenes]
        on_all = choose(scores, values, names)
        print(f"\n{default}: default {value:g}, tried {', '.join(f'{v:g}' for v in values)}; "
              f"chosen on all scenes: {on_all:g}")
        print(f"{'scene':20s} " + " ".join(f"{default}={v:<8g}" for v in values) +
              "  without it  relMSE with it / chosen on all")
        worst = 1.0
        for name in names:
            without = choose(scores, values, [n for n in names if n != name])
            loss = scores[name][without] / scores[name][on_all]
            worst = max(worst, loss)
            print(f"{name:20s} " + " ".join(f"{scores[name][v]:<11.3e}" for v in values) +
                  f"  {without:<10g}  {loss:.2f}")
        print(f"largest loss from leaving a scene out: {worst:.2f}")
        results[default] = {"values": values, "scores": scores, "chosen_on_all": on_all}
    if a.json:
        with open(a.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
