#!/usr/bin/env python3
"""Where should the two downlights of scenes/office-downlight.pbrt hang?

Moves them apart step by step along the room's length, renders the illuminance of the work plane
(scenes/office-downlight-sensors.txt: 35 points 0.8 m above the floor) at each spacing without an
image, and prints the mean illuminance and its uniformity U0 = minimum / mean (EN 12464-1 asks
at least 0.6 of an office's task area), each with the render's own error. The scene is read once;
each spacing only moves the lights and renders again.

  python3 examples/luminaire_sweep.py [SECONDS_PER_SPACING]
"""
import os
import sys

import numpy as np

import bpm

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, "..", "scenes")
# The documentation test runs every example briefly.
QUICK = os.environ.get("BPM_EXAMPLE_QUICK") == "1"


def main():
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 10.0
    scene = bpm.Scene(os.path.join(SCENES, "office-downlight.pbrt"))
    sensors = os.path.join(SCENES, "office-downlight-sensors.txt")
    budget = dict(iterations=2) if QUICK else dict(time=seconds)
    # The file hangs the lights at x = 1.3 m and 2.7 m (1.4 m apart), both at z = 1.5 m.
    spacing_now = 1.4
    print("spacing_m  E_mean_lux  E_min_lux  U0     error_of_U0")
    for spacing in (0.6, 1.4, 2.2, 3.0):
        step = (spacing - spacing_now) / 2
        scene.translate_light(0, (-step, 0, 0))
        scene.translate_light(1, (step, 0, 0))
        spacing_now = spacing
        r = scene.render(integrator="bpm", no_image=True, sensors=sensors, seed=1, **budget)
        if r.stop_reason == "interrupted":  # Ctrl-C ends this render; end the sweep too
            break
        plane, plane_error = r.sensors[:35], r.sensor_errors[:35]
        mean, lowest = plane.mean(), plane.argmin()
        u0 = plane[lowest] / mean
        # First-order error of min/mean from the two errors (the mean's is the smaller).
        u0_error = u0 * np.hypot(plane_error[lowest] / plane[lowest],
                                 np.sqrt((plane_error ** 2).sum()) / plane.sum())
        print(f"{spacing:9.1f}  {mean:10.1f}  {plane[lowest]:9.1f}  {u0:.3f}  {u0_error:.3f}")


if __name__ == "__main__":
    main()
