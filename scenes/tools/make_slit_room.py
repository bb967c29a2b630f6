#!/usr/bin/env python3
"""Writes scenes/slit-room.pbrt and its texture scenes/textures/wood.png: a closed room lit only
through a door left ajar (a slit of 8 cm) from a bright corridor, with an image-textured wooden
floor and glossy metal objects. Nearly all its light arrives after two or more bounces, and light
paths meet the textured floor and the rough metal at almost every bounce: the case where the cost
of a texel's spectrum and of the photon loop shows.
    python3 scenes/tools/make_slit_room.py
"""
import math
import os
import struct
import zlib

from make_scenes import OUT, box, quad

SIZE = 256  # texture side in texels


def wood_texel(u, v):
    """An sRGB-encoded wood colour at (u, v) in [0, 1)^2: planks along u with growth rings."""
    plank = int(v * 8)
    shift = (plank * 0.37) % 1.0
    x = (u + shift) * 3.0
    y = (v * 8) % 1.0
    rings = 0.5 + 0.5 * math.sin(40 * math.hypot(x % 1.0 - 0.5, y * 0.3 + 0.2 * plank % 1.0)
                                 + 3 * math.sin(7 * x))
    seam = 0.55 if y < 0.03 or y > 0.97 else 1.0
    tone = (0.78 + 0.08 * ((plank * 5) % 3)) * seam
    r = (0.55 + 0.25 * rings) * tone
    g = (0.36 + 0.17 * rings) * tone
    b = (0.20 + 0.09 * rings) * tone
    return [max(0, min(255, int(255 * c + 0.5))) for c in (r, g, b)]


def png_rgb(width, height, texel):
    """An 8-bit RGB PNG (no filtering, zlib level 9) of texel(u, v)."""
    rows = b""
    for j in range(height):
        row = bytearray([0])
        for i in range(width):
            row += bytes(texel((i + 0.5) / width, (j + 0.5) / height))
        rows += bytes(row)

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data +
                struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    return (b"\x89PNG\r\n\x1a\n" +
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))


def textured_quad(p0, p1, p2, p3, uv_scale):
    pts = "  ".join("%g %g %g" % v for v in (p0, p1, p2, p3))
    s = uv_scale
    return ('Shape "trianglemesh" "integer indices" [ 0 1 2 0 2 3 ] "point3 P" [ %s ]\n'
            '    "point2 uv" [ 0 0  %g 0  %g %g  0 %g ]\n' % (pts, s, s, s, s))


def slit_room():
    s = ("# A closed room lit only through a door left ajar: an 8 cm slit in the right wall opens on\n"
         "# a bright corridor. The floor is image-textured wood (textures/wood.png), a sphere and a\n"
         "# box are rough metal. Written by scenes/tools/make_slit_room.py.\n"
         "LookAt -1.6 1.5 -2.6   0.6 0.7 1.0   0 1 0\n"
         "Camera \"perspective\" \"float fov\" [ 60 ]\n"
         "Film \"rgb\" \"integer xresolution\" [ 320 ] \"integer yresolution\" [ 240 ]\n"
         "    \"string filename\" [ \"slit-room.exr\" ]\n"
         "Sampler \"independent\" \"integer pixelsamples\" [ 64 ]\nPixelFilter \"box\"\n"
         "Integrator \"bdpt\" \"integer maxdepth\" [ 10 ]\n\nWorldBegin\n\n")
    s += ('Texture "wood" "spectrum" "imagemap" "string filename" [ "textures/wood.png" ]\n'
          '    "string filter" [ "bilinear" ]\n')
    # The room: x in [-2, 2], y in [0, 2.6], z in [-3, 3]; the door in the wall x = 2 spans
    # z in [0.4, 1.2], y in [0, 2.1], and is open by 8 cm at its z = 0.4 edge.
    s += 'Material "diffuse" "rgb reflectance" [ 0.72 0.7 0.66 ]\n'
    s += quad((-2, 2.6, -3), (2, 2.6, -3), (2, 2.6, 3), (-2, 2.6, 3))    # ceiling
    s += quad((-2, 0, 3), (-2, 2.6, 3), (2, 2.6, 3), (2, 0, 3))          # back wall
    s += quad((-2, 0, -3), (-2, 0, 3), (-2, 2.6, 3), (-2, 2.6, -3))      # left wall
    s += quad((-2, 0, -3), (2, 0, -3), (2, 2.6, -3), (-2, 2.6, -3))      # front wall
    s += quad((2, 0, -3), (2, 2.6, -3), (2, 2.6, 0.4), (2, 0, 0.4))      # right wall before the door
    s += quad((2, 0, 1.2), (2, 2.6, 1.2), (2, 2.6, 3), (2, 0, 3))        # after it
    s += quad((2, 2.1, 0.4), (2, 2.6, 0.4), (2, 2.6, 1.2), (2, 2.1, 1.2))  # above it
    # The door leaf: closed from z = 0.48 on, leaving the slit z in [0.4, 0.48].
    s += 'Material "diffuse" "rgb reflectance" [ 0.5 0.42 0.34 ]\n'
    s += box(1.98, 0, 0.48, 2.02, 2.1, 1.2)
    # The corridor beyond: x in [2, 3.2], the same height, bright walls and a light on its ceiling.
    s += 'Material "diffuse" "rgb reflectance" [ 0.8 0.8 0.8 ]\n'
    s += quad((2, 0, -3), (3.2, 0, -3), (3.2, 0, 3), (2, 0, 3))          # corridor floor
    s += quad((3.2, 0, -3), (3.2, 2.6, -3), (3.2, 2.6, 3), (3.2, 0, 3))  # far wall
    s += quad((2, 2.6, -3), (3.2, 2.6, -3), (3.2, 2.6, 3), (2, 2.6, 3))  # corridor ceiling
    s += quad((2, 0, -3), (3.2, 0, -3), (3.2, 2.6, -3), (2, 2.6, -3))    # its ends
    s += quad((2, 0, 3), (3.2, 0, 3), (3.2, 2.6, 3), (2, 2.6, 3))
    s += ('AttributeBegin\n  AreaLightSource "diffuse" "rgb L" [ 240 224 192 ]\n'
          '  Material "diffuse" "rgb reflectance" [ 0 0 0 ]\n  '
          + quad((2.4, 2.59, 0.2), (2.8, 2.59, 0.2), (2.8, 2.59, 1.4), (2.4, 2.59, 1.4))
          + "AttributeEnd\n")
    # The floor: wooden planks, 1.5 m per texture repeat.
    s += 'Material "diffuse" "texture reflectance" "wood"\n'
    s += textured_quad((-2, 0, -3), (2, 0, -3), (2, 0, 3), (-2, 0, 3), 4)
    # Rough metal: a sphere (aluminium) and a box (copper, pbrt-v4's default conductor).
    s += ('AttributeBegin\n  Material "conductor" "spectrum eta" "metal-Al-eta" '
          '"spectrum k" "metal-Al-k" "float roughness" [ 0.08 ]\n'
          '  Translate 0.3 0.45 1.4\n  Shape "sphere" "float radius" [ 0.45 ]\nAttributeEnd\n')
    s += ('AttributeBegin\n  Material "conductor" "float roughness" [ 0.15 ]\n  '
          + box(-1.3, 0, 1.6, -0.6, 0.8, 2.3) + "AttributeEnd\n")
    return s


def main():
    os.makedirs(os.path.join(OUT, "textures"), exist_ok=True)
    with open(os.path.join(OUT, "textures", "wood.png"), "wb") as f:
        f.write(png_rgb(SIZE, SIZE, wood_texel))
    with open(os.path.join(OUT, "slit-room.pbrt"), "w") as f:
        f.write(slit_room())


if __name__ == "__main__":
    main()
