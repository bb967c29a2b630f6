#!/usr/bin/env python3
"""Writes the paper's test scenes (Room2 and the three Light Guides variants) in pbrt-v4 format.

The scenes are ours: they follow the descriptions of Zhdanov & Zhdanov 2020, section 5. Boxes are
written as triangle meshes so that pbrt-v4 reads the very same files.
    python3 scenes/tools/make_scenes.py   # rewrites scenes/room2.pbrt and scenes/light-guides-*.pbrt
"""
import os

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.dirname(HERE)


def box(x0, y0, z0, x1, y1, z1):
    """A closed box with outward normals (pbrt-v4 orientation: cross(p0 - p2, p1 - p2))."""
    p = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    # Each face is listed so that triangles (a, b, c) and (a, c, d) have outward normals.
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 7, 6, 2)]
    idx = []
    for a, b, c, d in faces:
        idx += [a, b, c, a, c, d]
    pts = "  ".join("%g %g %g" % v for v in p)
    return ('Shape "trianglemesh" "integer indices" [ %s ]\n    "point3 P" [ %s ]\n'
            % (" ".join(map(str, idx)), pts))


def quad(p0, p1, p2, p3):
    pts = "  ".join("%g %g %g" % v for v in (p0, p1, p2, p3))
    return 'Shape "trianglemesh" "integer indices" [ 0 1 2 0 2 3 ] "point3 P" [ %s ]\n' % pts


def header(comment, lookat, fov, res, maxdepth, name):
    return (comment + "LookAt %s\nCamera \"perspective\" \"float fov\" [ %g ]\n"
            "Film \"rgb\" \"integer xresolution\" [ %d ] \"integer yresolution\" [ %d ]\n"
            "    \"string filename\" [ \"%s.exr\" ]\n"
            "Sampler \"independent\" \"integer pixelsamples\" [ 64 ]\nPixelFilter \"box\"\n"
            "Integrator \"path\" \"integer maxdepth\" [ %d ]\n\nWorldBegin\n\n"
            % (lookat, fov, res[0], res[1], name, maxdepth))


def room2():
    s = header("# Room2: a closed, bright room (walls of albedo 0.85) with furniture and a ceiling lamp,\n"
               "# the paper's \"bounded and bright\" case: light bounces many times before it leaves\n"
               "# (it never does) or is absorbed, so forward photon maps grow with every bounce.\n"
               "# Written by scenes/tools/make_scenes.py.\n",
               "0.3 1.6 -2.35   -0.2 0.9 1.0   0 1 0", 62, (320, 240), 24, "room2")
    s += "# The lamp: a disk facing down just under the ceiling; its back reflects nothing.\n"
    s += ("AttributeBegin\n  Material \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n"
          "  AreaLightSource \"diffuse\" \"rgb L\" [ 40 38 34 ]\n"
          "  Translate 0 2.97 0.2\n  Rotate 90 1 0 0\n  Shape \"disk\" \"float radius\" [ 0.22 ]\nAttributeEnd\n\n")
    s += "# Walls, floor and ceiling: the inside of a 6 x 3 x 5 box.\n"
    s += "Material \"diffuse\" \"rgb reflectance\" [ 0.85 0.84 0.8 ]\n" + box(-3, 0, -2.5, 3, 3, 2.5)
    s += "AttributeBegin\n  Material \"diffuse\" \"rgb reflectance\" [ 0.55 0.42 0.3 ]  # floor rug\n"
    s += "  " + quad((-1.6, 0.002, -0.6), (-1.6, 0.002, 1.6), (1.6, 0.002, 1.6), (1.6, 0.002, -0.6)) + "AttributeEnd\n\n"
    s += "# A table: top and four legs\nAttributeBegin\n  Material \"diffuse\" \"rgb reflectance\" [ 0.7 0.55 0.4 ]\n"
    s += "  " + box(-0.8, 0.72, 0.3, 0.8, 0.78, 1.2)
    for x in (-0.75, 0.7):
        for z in (0.35, 1.1):
            s += "  " + box(x, 0, z, x + 0.05, 0.72, z + 0.05)
    s += "AttributeEnd\n"
    s += "# A cabinet against the back wall and a bookshelf at the left\n"
    s += "AttributeBegin\n  Material \"diffuse\" \"rgb reflectance\" [ 0.8 0.8 0.78 ]\n"
    s += "  " + box(1.2, 0, 1.9, 2.6, 1.1, 2.5) + "AttributeEnd\n"
    s += "AttributeBegin\n  Material \"diffuse\" \"rgb reflectance\" [ 0.45 0.55 0.7 ]\n"
    s += "  " + box(-3, 0, 0.2, -2.6, 2.0, 1.8)
    for y in (0.5, 1.0, 1.5):
        s += "  " + box(-2.6, y, 0.2, -2.3, y + 0.04, 1.8)
    s += "AttributeEnd\n"
    s += "# A low sofa at the right\nAttributeBegin\n  Material \"diffuse\" \"rgb reflectance\" [ 0.75 0.35 0.3 ]\n"
    s += "  " + box(2.0, 0, -1.2, 2.9, 0.45, 0.8) + "  " + box(2.6, 0.45, -1.2, 2.9, 0.9, 0.8)
    s += "AttributeEnd\n"
    return s


def guides(variant):
    """Three acrylic light guides (eta 1.49) with white extraction dots on their lower faces.
    variant 'inside': small lights inside the guides; 'outside': spot lights outside aimed into
    the guides' end faces; 'side': lights inside, camera looking into one guide's side face."""
    names = {"inside": "light-guides-inside", "outside": "light-guides-outside", "side": "light-guides-side"}
    what = {
        "inside": "the light sources are inside the light guides",
        "outside": "the light sources are outside, aimed into the guides' end faces",
        "side": "the light sources are inside the guides; the camera looks into a guide's side face",
    }[variant]
    if variant == "side":
        lookat, fov = "0 0.59 0.17   0.3 0.59 0.6   0 1 0", 60
    else:
        lookat, fov = "0 1.6 -2.4   0 0.45 0.3   0 1 0", 40
    s = header("# Light Guides (%s): transparent acrylic bars (eta 1.49) keep light in by total\n"
               "# internal reflection and let it out where white extraction dots scatter it.\n"
               "# Written by scenes/tools/make_scenes.py.\n" % what, lookat, fov, (320, 240), 64, names[variant])
    s += "# A closed light grey test room around the guides\nMaterial \"diffuse\" \"rgb reflectance\" [ 0.7 0.7 0.72 ]\n"
    s += box(-3, 0, -3, 3, 3, 2) + "\n"
    for i, (y, z) in enumerate(((0.3, 0.0), (0.55, 0.35), (0.8, 0.7))):
        x0, x1, h, d = -1.0, 1.0, 0.08, 0.25
        s += "# Guide %d\nAttributeBegin\n" % (i + 1)
        s += "  Material \"dielectric\" \"float eta\" [ 1.49 ]\n  " + box(x0, y, z, x1, y + h, z + d)
        s += "  Material \"diffuse\" \"rgb reflectance\" [ 0.9 0.9 0.9 ]\n"
        # Extraction dots: small white patches facing up, just above the guide's lower face.
        k = 0
        x = x0 + 0.25
        while x < x1 - 0.1:
            w = 0.03 + 0.004 * k  # wider away from the light, to even out the output
            s += "  " + quad((x, y + 0.004, z + 0.05), (x, y + 0.004, z + d - 0.05), (x + w, y + 0.004, z + d - 0.05),
                             (x + w, y + 0.004, z + 0.05))
            x += 0.15
            k += 1
        if variant in ("inside", "side"):
            s += ("  AttributeBegin\n    Material \"diffuse\" \"rgb reflectance\" [ 0 0 0 ]\n"
                  "    AreaLightSource \"diffuse\" \"rgb L\" [ %s ]\n    Translate %g %g %g\n"
                  "    Shape \"sphere\" \"float radius\" [ 0.025 ]\n  AttributeEnd\n"
                  % (["60 20 12", "15 50 20", "12 25 60"][i], x0 + 0.08, y + h / 2, z + d / 2))
        else:
            s += ("  LightSource \"spot\" \"point3 from\" [ %g %g %g ] \"point3 to\" [ %g %g %g ]\n"
                  "    \"float coneangle\" [ 8 ] \"float conedeltaangle\" [ 2 ] \"rgb I\" [ %s ]\n"
                  % (x0 - 0.3, y + h / 2, z + d / 2, x1, y + h / 2, z + d / 2, ["20 7 4", "5 17 7", "4 8 20"][i]))
        s += "AttributeEnd\n"
    return names[variant], s


def main():
    with open(os.path.join(OUT, "room2.pbrt"), "w") as f:
        f.write(room2())
    for v in ("inside", "outside", "side"):
        name, text = guides(v)
        with open(os.path.join(OUT, name + ".pbrt"), "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
