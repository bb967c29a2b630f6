#!/usr/bin/env python3
"""The three integrators at equal time on one scene, plotted with matplotlib.

Renders the scene with path, bpm and fpm for the same number of seconds each, records the total
relative error each one reports as it goes (delta, eq. 4 of the paper: noise, and for bpm and fpm
their bias estimate), and, with a reference image, measures each result's relative MSE against
it. Writes equal_time.png: delta against time on the left, the three images on the right.

  python3 examples/equal_time.py [SCENE] [SECONDS] [REFERENCE.exr]
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bpm  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
QUICK = os.environ.get("BPM_EXAMPLE_QUICK") == "1"  # the documentation test's brief run


def rel_mse(image, reference):
    """As `bpm compare`: mean over pixels and channels of (a - b)^2 / (b^2 + 0.01)."""
    return float(np.mean((image - reference) ** 2 / (reference ** 2 + 0.01)))


def main():
    scene_path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "..", "scenes",
                                                                   "caustic-sphere.pbrt")
    seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 20.0
    reference = bpm.read_exr(sys.argv[3]) if len(sys.argv) > 3 else None
    scene = bpm.Scene(scene_path)
    size = dict(resolution=(32, 24), iterations=3) if QUICK else dict(time=seconds)
    results = {}
    for integrator in ("path", "bpm", "fpm"):
        curve = []
        r = scene.render(integrator=integrator, seed=1,
                         progress=lambda p: curve.append((p["seconds"], p["delta"], p["passes"])),
                         **size)
        if r.stop_reason == "interrupted":  # Ctrl-C ends this render; end the comparison too
            break
        results[integrator] = (r, curve)
        delta = r.stats["result"]["relative_error_delta_total"]
        line = f"{integrator:5s} {r.stats['result']['passes']:6d} passes  delta {delta:.4f}"
        if reference is not None:
            line += f"  relMSE {rel_mse(r.image, reference):.3e}"
        print(line)

    fig, axes = plt.subplots(1, 4, figsize=(16, 4), gridspec_kw={"width_ratios": [1.4, 1, 1, 1]})
    for integrator, (r, curve) in results.items():
        # delta from fewer than five passes says little (the render's own stopping rule waits
        # for five too).
        settled = [c for c in curve if c[2] >= 5] or curve
        if not settled:
            continue
        t, delta, _ = zip(*settled)
        axes[0].loglog(t, delta, label=integrator)
    axes[0].set_xlabel("seconds")
    axes[0].set_ylabel("total relative error delta")
    axes[0].legend()
    for ax, (integrator, (r, _)) in zip(axes[1:], results.items()):
        ax.imshow(np.clip(r.image, 0, 1) ** (1 / 2.2))  # a plain gamma for the picture
        ax.set_title(integrator)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig("equal_time.png", dpi=80)
    print("wrote equal_time.png")


if __name__ == "__main__":
    main()
