#!/usr/bin/env python3
"""Writes scenes/textures/waves-normal.pfm: a tangent-space normal map of ripples along u,
n = normalize(-a k cos(k u), 0, 1) with k = 2 pi 4 and a k = 0.6, as 0.5 + 0.5 n (float RGB)."""
import math
import struct
import sys

W, H = 256, 16
out = sys.argv[1] if len(sys.argv) > 1 else "scenes/textures/waves-normal.pfm"
with open(out, "wb") as f:
    f.write(b"PF\n%d %d\n-1.0\n" % (W, H))
    for _ in range(H):  # rows from the bottom; every row the same
        for x in range(W):
            u = (x + 0.5) / W
            nx, nz = -0.6 * math.cos(2 * math.pi * 4 * u), 1.0
            l = math.hypot(nx, nz)
            f.write(struct.pack("<3f", 0.5 + 0.5 * nx / l, 0.5, 0.5 + 0.5 * nz / l))
