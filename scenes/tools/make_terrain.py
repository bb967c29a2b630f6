#!/usr/bin/env python3
"""Writes scenes/meshes/terrain.ply, a 4 x 4 square in the xz plane at y = 0 (two triangles,
uv 0..1, normal +y), and scenes/textures/terrain-height.pfm, a smooth height field over it:
h(u, v) = 0.5 + 0.25 sin(2 pi 2 u) sin(2 pi 3 v) + 0.25 cos(2 pi u) (float, one channel as RGB),
periodic in u and v so that its repeat wrap is seamless."""
import math
import struct
import sys

root = sys.argv[1] if len(sys.argv) > 1 else "scenes"
with open(f"{root}/meshes/terrain.ply", "w") as f:
    f.write("ply\nformat ascii 1.0\nelement vertex 4\n")
    for p in ("x", "y", "z", "u", "v"):
        f.write(f"property float {p}\n")
    f.write("element face 2\nproperty list uchar int vertex_indices\nend_header\n")
    # Counter-clockwise seen from above (+y): the normal points up.
    for x, z, u, v in ((-2, 2, 0, 0), (2, 2, 1, 0), (2, -2, 1, 1), (-2, -2, 0, 1)):
        f.write(f"{x} 0 {z} {u} {v}\n")
    f.write("3 0 1 2\n3 0 2 3\n")

W = H = 128
with open(f"{root}/textures/terrain-height.pfm", "wb") as f:
    f.write(b"PF\n%d %d\n-1.0\n" % (W, H))
    for row in range(H):  # rows from the bottom
        v = 1 - (row + 0.5) / H
        for x in range(W):
            u = (x + 0.5) / W
            h = 0.5 + 0.25 * math.sin(2 * math.pi * 2 * u) * math.sin(2 * math.pi * 3 * v) \
                + 0.25 * math.cos(2 * math.pi * u)
            f.write(struct.pack("<3f", h, h, h))
