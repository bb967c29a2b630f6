#!/usr/bin/env python3
"""Writes scenes/meshes/curves-tuft.pbrt: the curve shapes of scenes/curves.pbrt. A tuft of 64 thin
flat (ray-facing) hairs tapering from 6 to 1 mm; eight cylinder strands 12 mm wide arching over
it, as cubic B-splines; twelve grass blades as ribbons 20 to 3 mm wide that twist with their
normals; and a quadratic Bezier arc. Positions come from a fixed linear congruential sequence, so
the file is the same on every run."""
import math
import sys

root = sys.argv[1] if len(sys.argv) > 1 else "scenes"
state = 12345


def rand():
    global state
    state = (1103515245 * state + 12345) % (1 << 31)
    return state / float(1 << 31)


def pts(ps):
    return " ".join(f"{x:.4f} {y:.4f} {z:.4f}" for x, y, z in ps)


out = ["# Written by scenes/tools/make_curves.py: the curves of scenes/curves.pbrt."]
out.append('AttributeBegin\n  Material "diffuse" "rgb reflectance" [0.7 0.45 0.2]')
for i in range(64):
    x0, z0 = -1.0 + 0.25 * (rand() - 0.5), 0.25 * (rand() - 0.5)
    h = 0.8 + 0.5 * rand()
    a = 2 * math.pi * rand()
    lean = 0.2 + 0.3 * rand()
    dx, dz = lean * math.cos(a), lean * math.sin(a)
    p = [(x0, 0, z0), (x0 + 0.1 * dx, h / 3, z0 + 0.1 * dz),
         (x0 + 0.5 * dx, 2 * h / 3, z0 + 0.5 * dz), (x0 + dx, h, z0 + dz)]
    out.append(f'  Shape "curve" "string type" "flat" "float width0" 0.006 "float width1" 0.001\n'
               f'    "point3 P" [{pts(p)}]')
out.append("AttributeEnd")
out.append('AttributeBegin\n  Material "diffuse" "rgb reflectance" [0.2 0.5 0.7]')
for i in range(8):
    z = -0.3 + 0.1 * i
    p = [(-0.6 + 0.3 * k, 0.15 + 0.5 * abs(math.sin(0.9 * k + 0.4 * i)), z + 0.05 * math.sin(k))
         for k in range(6)]
    out.append(f'  Shape "curve" "string type" "cylinder" "string basis" "bspline" '
               f'"float width" 0.012\n    "point3 P" [{pts(p)}]')
out.append("AttributeEnd")
out.append('AttributeBegin\n  Material "diffuse" "rgb reflectance" [0.3 0.65 0.25]')
for i in range(12):
    x0, z0 = 0.8 + 0.5 * rand(), -0.2 + 0.4 * rand()
    h = 0.9 + 0.6 * rand()
    b = 0.1 + 0.3 * rand()
    p = [(x0, 0, z0), (x0, h / 3, z0), (x0 + b / 2, 2 * h / 3, z0 + 0.05), (x0 + b, h, z0 + 0.1)]
    t = math.pi * rand()
    n = f"0 0 -1  {math.sin(t):.4f} 0 {-math.cos(t):.4f}"
    out.append(f'  Shape "curve" "string type" "ribbon" "float width0" 0.02 "float width1" 0.003\n'
               f'    "point3 P" [{pts(p)}] "normal N" [{n}]')
out.append("AttributeEnd")
out.append('AttributeBegin\n  Material "diffuse" "rgb reflectance" [0.75 0.2 0.2]\n'
           '  Shape "curve" "string type" "cylinder" "integer degree" 2 "float width" 0.015\n'
           '    "point3 P" [-0.4 0.02 -0.6  0 0.7 -0.6  0.4 0.02 -0.6  0.6 0.3 -0.7  0.8 0.02 -0.8]\n'
           'AttributeEnd')
with open(f"{root}/meshes/curves-tuft.pbrt", "w") as f:
    f.write("\n".join(out) + "\n")
