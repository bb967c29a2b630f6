#!/usr/bin/env python3
"""Writes a furnished interior of over a million triangles into OUTDIR (default build/interior):
interior.pbrt and binary PLY meshes. A 6 x 3 x 5 room with a glazed window (a sun and a sky
outside), three strip lights on the ceiling, a rug (a 500 x 500 grid), eight cushions with a
normal-mapped fabric, a glass vase, a bowl of fruit and a table. Used by bench/interior_load.py
(load time and peak memory beside pbrt-v4); not kept in the repository (about 30 MB)."""
import math
import os
import shutil
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def write_ply(path, verts, uvs, tris):
    with open(path, "wb") as f:
        f.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 "property float u\nproperty float v\nelement face %d\n"
                 "property list uchar int vertex_indices\nend_header\n"
                 % (len(verts), len(tris))).encode())
        f.write(b"".join(struct.pack("<5f", *p, *t) for p, t in zip(verts, uvs)))
        f.write(b"".join(struct.pack("<B3i", 3, *t) for t in tris))


def grid(nu, nv, point):
    """A (nu + 1) x (nv + 1) grid of point(u, v), u and v in [0, 1], two triangles a cell."""
    verts, uvs, tris = [], [], []
    for j in range(nv + 1):
        for i in range(nu + 1):
            u, v = i / nu, j / nv
            verts.append(point(u, v))
            uvs.append((u, v))
    for j in range(nv):
        for i in range(nu):
            q = j * (nu + 1) + i
            tris += [(q, q + 1, q + nu + 2), (q, q + nu + 2, q + nu + 1)]
    return verts, uvs, tris


def ellipsoid(nu, nv, rx, ry, rz):
    def p(u, v):
        phi, theta = 2 * math.pi * u, math.pi * v
        return (rx * math.sin(theta) * math.cos(phi), -ry * math.cos(theta),
                rz * math.sin(theta) * math.sin(phi))
    return grid(nu, nv, p)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "..", "..", "build", "interior")
    os.makedirs(out, exist_ok=True)
    shutil.copy(os.path.join(HERE, "..", "textures", "waves-normal.pfm"), out)
    write_ply(os.path.join(out, "rug.ply"),
              *grid(500, 500, lambda u, v: (-1.5 + 3 * u, 0.01 + 0.004 * math.sin(40 * u) *
                                            math.sin(40 * v), -1.2 + 2.4 * v)))
    write_ply(os.path.join(out, "cushion.ply"), *ellipsoid(200, 100, 0.25, 0.08, 0.25))
    write_ply(os.path.join(out, "vase.ply"), *grid(256, 160, lambda u, v: (
        (0.08 + 0.05 * math.sin(math.pi * v)) * math.cos(2 * math.pi * u), 0.4 * v,
        -(0.08 + 0.05 * math.sin(math.pi * v)) * math.sin(2 * math.pi * u))))
    write_ply(os.path.join(out, "fruit.ply"), *ellipsoid(120, 80, 0.05, 0.05, 0.05))
    s = ["# A furnished interior of over a million triangles (scenes/tools/make_interior.py).",
         'LookAt 2.6 1.5 2.2  -0.5 0.6 -0.8  0 1 0',
         'Camera "perspective" "float fov" 60',
         'Film "rgb" "integer xresolution" 160 "integer yresolution" 120 "string filename" '
         '"interior.exr"',
         'Integrator "path" "integer maxdepth" 6',
         "WorldBegin",
         'LightSource "distant" "point3 from" [-1 2 -3] "point3 to" [0 0 0] "blackbody L" 5500 '
         '"float illuminance" 4',
         'LightSource "infinite" "rgb L" [0.4 0.5 0.7] "float illuminance" 1.5']
    quad = ('Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point3 P" [%s]')
    def q(*pts):
        return quad % "  ".join("%g %g %g" % p for p in pts)
    s += ['Material "diffuse" "rgb reflectance" [0.6 0.55 0.5]',
          q((-3, 0, -2.5), (-3, 0, 2.5), (3, 0, 2.5), (3, 0, -2.5)),        # floor
          q((-3, 3, -2.5), (3, 3, -2.5), (3, 3, 2.5), (-3, 3, 2.5)),        # ceiling
          q((-3, 0, 2.5), (-3, 3, 2.5), (3, 3, 2.5), (3, 0, 2.5)),          # front
          q((-3, 0, -2.5), (-3, 3, -2.5), (-3, 3, 2.5), (-3, 0, 2.5)),      # left
          q((3, 0, -2.5), (3, 0, 2.5), (3, 3, 2.5), (3, 3, -2.5)),          # right
          # the back wall around a 2 x 1.4 window from x = -1 to 1, y = 0.9 to 2.3
          q((-3, 0, -2.5), (3, 0, -2.5), (3, 0.9, -2.5), (-3, 0.9, -2.5)),
          q((-3, 2.3, -2.5), (3, 2.3, -2.5), (3, 3, -2.5), (-3, 3, -2.5)),
          q((-3, 0.9, -2.5), (-1, 0.9, -2.5), (-1, 2.3, -2.5), (-3, 2.3, -2.5)),
          q((1, 0.9, -2.5), (3, 0.9, -2.5), (3, 2.3, -2.5), (1, 2.3, -2.5)),
          'Material "thindielectric" "float eta" 1.5',
          q((-1, 0.9, -2.5), (1, 0.9, -2.5), (1, 2.3, -2.5), (-1, 2.3, -2.5))]
    for x in (-1.5, 0, 1.5):
        s += ["AttributeBegin", 'AreaLightSource "diffuse" "blackbody L" 4000 "float power" 40',
              q((x - 0.6, 2.98, -0.05), (x + 0.6, 2.98, -0.05), (x + 0.6, 2.98, 0.05),
                (x - 0.6, 2.98, 0.05)), "AttributeEnd"]
    s += ["AttributeBegin", 'Material "diffuse" "rgb reflectance" [0.5 0.15 0.1]',
          'Shape "plymesh" "string filename" "rug.ply"', "AttributeEnd",
          "AttributeBegin", 'Material "diffuse" "rgb reflectance" [0.45 0.3 0.2]',
          'Translate 0 0.7 -0.8',
          'Shape "trianglemesh" "integer indices" [0 1 2 0 2 3] "point3 P" '
          '[-0.8 0 -0.5  0.8 0 -0.5  0.8 0 0.5  -0.8 0 0.5]', "AttributeEnd"]
    fabrics = [(0.2, 0.3, 0.6), (0.6, 0.5, 0.2), (0.3, 0.5, 0.3), (0.55, 0.2, 0.3)]
    for k in range(8):
        x, z = -2.4 + 0.6 * (k % 4) + 0.1 * (k // 4), 1.6 - 0.5 * (k // 4)
        s += ["AttributeBegin",
              'Material "diffuse" "rgb reflectance" [%g %g %g] "string normalmap" '
              '"waves-normal.pfm"' % fabrics[k % 4],
              "Translate %g %g %g" % (x, 0.09 + 0.16 * (k // 4), z),
              'Shape "plymesh" "string filename" "cushion.ply"', "AttributeEnd"]
    s += ["AttributeBegin", 'Material "dielectric" "float eta" 1.5', "Translate 0.4 0.7 -0.8",
          'Shape "plymesh" "string filename" "vase.ply"', "AttributeEnd"]
    for k in range(10):
        a = 2 * math.pi * k / 10
        s += ["AttributeBegin", 'Material "coateddiffuse" "rgb reflectance" [0.7 %g 0.1] '
              '"float roughness" 0.05' % (0.2 + 0.05 * k),
              "Translate %g 0.75 %g" % (-0.3 + 0.12 * math.cos(a), -0.8 + 0.12 * math.sin(a)),
              'Shape "plymesh" "string filename" "fruit.ply"', "AttributeEnd"]
    with open(os.path.join(out, "interior.pbrt"), "w") as f:
        f.write("\n".join(s) + "\n")


if __name__ == "__main__":
    main()
