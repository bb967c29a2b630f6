#!/usr/bin/env python3
"""A sweep from Python: one scene read once and rendered at several light scales, against the
same renders each reading the file again (what a loop over `bpm render` does). Prints the median
seconds per step of each, their ratio, and where a step's time goes (the JSON record's stages).

  PYTHONPATH=build/python /usr/bin/python3 bench/python_sweep.py [SCENE ...] [--steps N]

Each step renders 1 pass at 64x64 with path, so that reading and building the scene show."""
import argparse
import os
import statistics
import time

import bpm

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def sweep(scene_path, steps, read_once):
    times, stages = [], []
    scene = bpm.Scene(scene_path) if read_once else None
    for k in range(steps):
        t = time.perf_counter()
        s = scene if read_once else bpm.Scene(scene_path)
        if s.lights:
            s.set_light(0, "float scale", 1.0 + 0.1 * k)
        r = s.render(integrator="path", resolution=(64, 64), spp=1, seed=k)
        times.append(time.perf_counter() - t)
        stages.append(r.stats["stages_s"])
    mid = {key: statistics.median(st[key] for st in stages) for key in stages[0]}
    return statistics.median(times), mid


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="*", default=[os.path.join(ROOT, "scenes", n) for n in
                                                  ("water-box.pbrt", "office-downlight.pbrt")])
    ap.add_argument("--steps", type=int, default=9)
    a = ap.parse_args()
    print(f"{'scene':28s} {'read each step s':>17s} {'read once s':>12s} {'ratio':>6s}   "
          "stages of a step read once (parse, build, render)")
    for path in a.scenes:
        again, _ = sweep(path, a.steps, read_once=False)
        once, st = sweep(path, a.steps, read_once=True)
        print(f"{os.path.basename(path):28s} {again:17.4f} {once:12.4f} {once / again:6.2f}   "
              f"{st['parse']:.4f} {st['build']:.4f} {st['render']:.4f}")


if __name__ == "__main__":
    main()
