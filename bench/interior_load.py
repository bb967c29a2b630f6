#!/usr/bin/env python3
"""Load time and peak memory of a furnished interior of over a million triangles, bpm beside
pbrt-v4, in one run on the same machine.

The scene (written by scenes/tools/make_interior.py into OUTDIR, about 30 MB of binary PLY):
a room lit through a glazed window by a sun and sky and by three strip lights on the ceiling; a
rug, eight cushions with a bump-mapped fabric (normal map), a glass vase, a bowl of fruit, a table.
Each renderer renders it at 1 sample per pixel (bpm: each integrator, one pass or iteration), so
that the wall time is mostly loading; /usr/bin/time gives the wall time and peak resident memory,
bpm's JSON record its parse and build times.

  bench/interior_load.py [--out OUTDIR] [--pbrt PATH] [--bpm PATH]
"""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def timed(cmd):
    """Runs cmd under /usr/bin/time: (exit status, wall seconds, peak RSS in MiB)."""
    r = subprocess.run(["/usr/bin/time", "-f", "%e %M"] + cmd, capture_output=True, text=True)
    last = r.stderr.strip().splitlines()[-1].split()
    return r.returncode, float(last[0]), float(last[1]) / 1024


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "interior"))
    ap.add_argument("--pbrt", default=os.path.join(ROOT, "..", "shared", "tools", "pbrt-v4", "pbrt"))
    ap.add_argument("--bpm", default=os.path.join(ROOT, "build", "bpm"))
    a = ap.parse_args()
    subprocess.run([sys.executable, os.path.join(ROOT, "scenes", "tools", "make_interior.py"), a.out],
                   check=True)
    scene = os.path.join(a.out, "interior.pbrt")
    rows = []
    if os.path.exists(a.pbrt):
        rc, wall, rss = timed([a.pbrt, "--quiet", "--nthreads", "2", "--spp", "1", "--outfile",
                               os.path.join(a.out, "pbrt.exr"), scene])
        rows.append(("pbrt-v4 (path, 1 spp)", rc, wall, rss, ""))
    for integrator in ("path", "bpm", "fpm"):
        out = os.path.join(a.out, "bpm-" + integrator + ".exr")
        rc, wall, rss = timed([a.bpm, "render", scene, "-q", "--threads", "2", "--integrator",
                               integrator, "--spp", "1", "-o", out])
        load = ""
        try:
            rec = json.load(open(out[:-4] + ".json"))
            t = rec["stages_s"]
            load = "%.2f s parse, %.2f s build" % (t["parse"], t["build"])
        except (OSError, ValueError, KeyError):
            pass
        rows.append(("bpm " + integrator + " (1 pass)", rc, wall, rss, load))
    print("| renderer | exit | wall s | peak RSS MiB | load |")
    print("| --- | --- | --- | --- | --- |")
    for name, rc, wall, rss, load in rows:
        print("| %s | %d | %.2f | %.0f | %s |" % (name, rc, wall, rss, load))
    if rows and rows[0][0].startswith("pbrt"):
        for name, rc, wall, rss, _ in rows[1:]:
            print("%s / pbrt-v4: wall %.2f, peak memory %.2f" % (name, wall / rows[0][2],
                                                                rss / rows[0][3]))


if __name__ == "__main__":
    main()
