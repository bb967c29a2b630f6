#!/usr/bin/env python3
"""Writes the equal-time benchmark's own scenes in pbrt-v4 format (bench/equal_time):
- spot-facets: a spot light through a faceted glass object onto a glossy coated floor;
- water-box: a wavy water surface over a diffuse floor in a closed box, under a tiny bright light;
- lamp-room: a room lit only indirectly, by a lamp inside a shade aimed at the ceiling, with a
  glass egg on a table;
- spot-lens-fog: a spot light through a glass lens into a foggy room (a volumetric caustic);
- underwater: a spot light and a dim sky over a wavy water surface, seen from inside murky water;
- smoke: a plume of smoke (a uniformgrid medium) over a floor, lit by a spot light and a sky panel;
- shelf-room: a living room lit by one small bright sphere, thin open shelves on a wall, a sofa, a
  low table and red-tinted glass objects;
- kitchen: a kitchen lit by a window and three strip lights under its wall cabinets, with glass
  on the counter and the table.
    python3 scenes/tools/make_equal_time_scenes.py   # rewrites those eight scenes/*.pbrt
"""
import math
import os

from make_scenes import OUT, box, header, quad


def outward(points, tris, inside):
    """Orders each triangle so that pbrt-v4's normal cross(p0 - p2, p1 - p2) points away from
    the point `inside` (for a closed convex mesh) or along +y when inside is None."""
    def sub(a, b):
        return [a[i] - b[i] for i in range(3)]

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

    out = []
    for a, b, c in tris:
        n = cross(sub(points[a], points[c]), sub(points[b], points[c]))
        if inside is None:
            away = n[1]
        else:
            centre = [(points[a][i] + points[b][i] + points[c][i]) / 3 for i in range(3)]
            away = sum(n[i] * (centre[i] - inside[i]) for i in range(3))
        out.append((a, b, c) if away > 0 else (b, a, c))
    return out


def room_walls(x0, x1, h, z0, z1):
    """A closed room's ceiling and four walls, facing in: x in [x0, x1], z in [z0, z1], height h."""
    return (quad((x0, h, z0), (x1, h, z0), (x1, h, z1), (x0, h, z1)) +      # ceiling
            quad((x0, 0, z1), (x0, h, z1), (x1, h, z1), (x1, 0, z1)) +      # back wall
            quad((x0, 0, z0), (x0, 0, z1), (x0, h, z1), (x0, h, z0)) +      # left wall
            quad((x1, 0, z0), (x1, h, z0), (x1, h, z1), (x1, 0, z1)) +      # right wall
            quad((x0, 0, z0), (x1, 0, z0), (x1, h, z0), (x0, h, z0)))       # front wall


def room_floor(x0, x1, z0, z1):
    return quad((x0, 0, z0), (x0, 0, z1), (x1, 0, z1), (x1, 0, z0))


def mesh(points, tris):
    idx = " ".join("%d %d %d" % t for t in tris)
    pts = "  ".join("%.5g %.5g %.5g" % tuple(p) for p in points)
    return 'Shape "trianglemesh" "integer indices" [ %s ]\n    "point3 P" [ %s ]\n' % (idx, pts)


def icosahedron(centre, r):
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    s = r / math.sqrt(1 + t * t)
    pts = [[centre[0] + s * x, centre[1] + s * y, centre[2] + s * z] for x, y, z in v]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    return mesh(pts, outward(pts, faces, centre))


def spot_facets():
    s = header("# A spot light through a faceted glass icosahedron onto a glossy coated floor: the\n"
               "# caustic reaches the camera through the coat's glossy reflection.\n",
               "0 1.4 -2.6   0 0.3 0.4   0 1 0", 40, (256, 256), 8, "spot-facets")
    s += ('LightSource "spot" "point3 from" [ -0.6 2.4 -0.2 ] "point3 to" [ 0 0.35 0.4 ]\n'
          '    "float coneangle" [ 12 ] "float conedeltaangle" [ 3 ] "rgb I" [ 60 60 60 ]\n')
    s += 'LightSource "point" "point3 from" [ 1.5 2.5 -2 ] "rgb I" [ 0.6 0.6 0.6 ]\n'
    s += ('Material "coateddiffuse" "rgb reflectance" [ 0.45 0.4 0.35 ] "float roughness" [ 0.05 ]\n')
    s += quad((-3, 0, -3), (-3, 0, 3), (3, 0, 3), (3, 0, -3))
    s += 'Material "diffuse" "rgb reflectance" [ 0.6 0.62 0.65 ]\n'
    s += quad((-3, 0, 2), (3, 0, 2), (3, 3, 2), (-3, 3, 2))
    s += 'AttributeBegin\n  Material "dielectric" "float eta" [ 1.5 ]\n'
    s += "  " + icosahedron((0, 0.35, 0.4), 0.35)
    s += "AttributeEnd\n"
    return s


def water_box():
    s = header("# A wavy water surface over a diffuse floor in a closed box, lit by a tiny, very bright\n"
               "# light under the ceiling: the floor is lit through the water (specular-diffuse-\n"
               "# specular paths to the camera).\n",
               "0.5 0.9 -0.9   0.5 0.2 0.5   0 1 0", 50, (256, 256), 10, "water-box")
    s += ('AttributeBegin\n  AreaLightSource "diffuse" "rgb L" [ 1200 1200 1200 ]\n'
          '  Material "diffuse" "rgb reflectance" [ 0 0 0 ]\n  '
          + quad((0.48, 0.999, 0.48), (0.52, 0.999, 0.48), (0.52, 0.999, 0.52), (0.48, 0.999, 0.52))
          + "AttributeEnd\n")
    s += 'Material "diffuse" "rgb reflectance" [ 0.75 0.75 0.7 ]\n'
    for q in [((0, 0, 0), (0, 0, 1), (1, 0, 1), (1, 0, 0)),   # floor
              ((0, 1, 0), (1, 1, 0), (1, 1, 1), (0, 1, 1)),   # ceiling
              ((0, 0, 1), (0, 1, 1), (1, 1, 1), (1, 0, 1)),   # back
              ((0, 0, -1.2), (1, 0, -1.2), (1, 1, -1.2), (0, 1, -1.2))]:  # front, behind the camera
        s += quad(*q)
    s += 'Material "diffuse" "rgb reflectance" [ 0.7 0.2 0.15 ]\n'
    s += quad((0, 0, -1.2), (0, 1, -1.2), (0, 1, 1), (0, 0, 1))
    s += 'Material "diffuse" "rgb reflectance" [ 0.2 0.6 0.25 ]\n'
    s += quad((1, 0, -1.2), (1, 0, 1), (1, 1, 1), (1, 1, -1.2))
    n = 48
    pts, tris = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = i / n, j / n
            y = 0.3 + 0.012 * math.sin(17 * x + 3 * z) + 0.008 * math.cos(23 * z - 5 * x)
            pts.append([x, y, z])
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            tris += [(a, a + 1, a + n + 2), (a, a + n + 2, a + n + 1)]
    s += 'AttributeBegin\n  Material "dielectric" "float eta" [ 1.33 ]\n'
    s += "  " + mesh(pts, outward(pts, tris, None)) + "AttributeEnd\n"
    return s


def lamp_room():
    s = header("# A room lit only indirectly: a small bright lamp inside an opaque shade aimed at the\n"
               "# ceiling, a glass egg on a table. Almost every path to the camera has two or more\n"
               "# diffuse bounces.\n",
               "1.7 1.6 -2.7   0.0 0.8 1.2   0 1 0", 55, (256, 256), 10, "lamp-room")
    s += 'Material "diffuse" "rgb reflectance" [ 0.75 0.73 0.7 ]\n'
    s += room_walls(-2, 2, 3, -3, 3)
    s += 'Material "diffuse" "rgb reflectance" [ 0.45 0.35 0.25 ]\n'
    s += room_floor(-2, 2, -3, 3)
    s += 'Material "diffuse" "rgb reflectance" [ 0.5 0.4 0.3 ]\n' + box(-0.5, 0, 0.8, 0.7, 0.7, 1.6)
    # The lamp: a shade (open cylinder, dark outside and inside) around a small light facing up.
    s += ('AttributeBegin\n  Translate -1.4 0 2.2\n'
          '  Material "diffuse" "rgb reflectance" [ 0.2 0.2 0.2 ]\n'
          '  ' + box(-0.03, 0, -0.03, 0.03, 1.4, 0.03) +
          '  AttributeBegin\n    Translate 0 1.4 0\n    Rotate -90 1 0 0\n'
          '    Shape "cylinder" "float radius" [ 0.22 ] "float zmin" [ 0 ] "float zmax" [ 0.35 ]\n'
          '    AreaLightSource "diffuse" "rgb L" [ 240 208 160 ]\n'
          '    Translate 0 0 0.05\n    Shape "disk" "float radius" [ 0.12 ]\n'
          '  AttributeEnd\nAttributeEnd\n')
    s += ('AttributeBegin\n  Material "dielectric" "float eta" [ 1.5 ]\n'
          '  Translate 0.1 0.86 1.2\n  Scale 1 1.3 1\n  Shape "sphere" "float radius" [ 0.12 ]\n'
          'AttributeEnd\n')
    return s


def spot_lens_fog():
    s = header('# A spot light shining down through a glass lens (a flattened sphere) into a closed room\n'
               '# full of thin fog: the lens focuses the cone into a bright waist in the fog and a spot\n'
               '# on the floor (a volumetric caustic of a point light, which no path from the camera\n'
               '# finds). The camera stands in the fog.\n'
               'MakeNamedMedium "fog" "string type" "homogeneous" "rgb sigma_a" [ 0.01 0.01 0.01 ]\n'
               '    "rgb sigma_s" [ 0.08 0.08 0.08 ] "float g" [ 0.4 ]\n'
               'MediumInterface "" "fog"\n',
               "0 1.5 -3.6   0 1.1 0.5   0 1 0", 55, (256, 192), 8, "spot-lens-fog")
    s += 'MediumInterface "fog"\n'
    s += ('LightSource "spot" "point3 from" [ 0 2.9 0.5 ] "point3 to" [ 0 0 0.5 ]\n'
          '    "float coneangle" [ 18 ] "float conedeltaangle" [ 3 ] "blackbody I" [ 5000 ]\n'
          '    "float scale" [ 12 ]\n')
    s += 'LightSource "point" "point3 from" [ -1.5 2.6 -2.5 ] "blackbody I" [ 3000 ] "float scale" [ 0.3 ]\n'
    s += 'Material "diffuse" "rgb reflectance" [ 0.6 0.6 0.6 ]\n' + box(-2.5, 0, -4, 2.5, 3, 3)
    s += ('AttributeBegin\n  MediumInterface "" "fog"\n  Material "dielectric" "float eta" [ 1.5 ]\n'
          '  Translate 0 2.1 0.5\n  Scale 1 0.3 1\n  Shape "sphere" "float radius" [ 0.5 ]\n'
          'AttributeEnd\n')
    s += ('AttributeBegin\n  Material "diffuse" "rgb reflectance" [ 0.7 0.3 0.2 ]\n'
          '  Translate 1.1 0.4 1.2\n  Shape "sphere" "float radius" [ 0.4 ]\nAttributeEnd\n')
    return volpath(s)


def underwater():
    s = header('# Inside murky water under a wavy surface: a spot light above the water shines down through\n'
               '# the waves (caustics on the sand and shafts in the water), a dim sky panel lights the\n'
               '# rest. The water body is the tank below the surface, an interface between water\n'
               '# (inside, below) and air; the camera is in the water.\n'
               'MakeNamedMedium "water" "string type" "homogeneous" "rgb sigma_a" [ 0.25 0.06 0.08 ]\n'
               '    "rgb sigma_s" [ 0.2 0.25 0.22 ] "float g" [ 0.7 ]\n'
               'MediumInterface "" "water"\n',
               "0 0.55 -1.8   0 0.8 0.8   0 1 0", 60, (256, 192), 10, "underwater")
    s += ('LightSource "spot" "point3 from" [ 0.4 3.5 0.6 ] "point3 to" [ 0 0 0.8 ]\n'
          '    "float coneangle" [ 14 ] "float conedeltaangle" [ 2 ] "blackbody I" [ 5500 ]\n'
          '    "float scale" [ 40 ]\n')
    s += ('AttributeBegin\n  AreaLightSource "diffuse" "rgb L" [ 0.4 0.5 0.7 ]\n'
          '  Material "diffuse" "rgb reflectance" [ 0 0 0 ]\n  '
          + quad((-2, 4, -2), (-2, 4, 2), (2, 4, 2), (2, 4, -2)) + "AttributeEnd\n")
    s += 'Material "diffuse" "rgb reflectance" [ 0.7 0.65 0.5 ]\n'
    s += quad((-2, 0, -2), (-2, 0, 2), (2, 0, 2), (2, 0, -2))  # sand
    s += 'Material "diffuse" "rgb reflectance" [ 0.35 0.4 0.4 ]\n'
    for q in [((-2, 0, 2), (-2, 2, 2), (2, 2, 2), (2, 0, 2)), ((-2, 0, -2), (2, 0, -2), (2, 2, -2), (-2, 2, -2)),
              ((-2, 0, -2), (-2, 2, -2), (-2, 2, 2), (-2, 0, 2)), ((2, 0, -2), (2, 0, 2), (2, 2, 2), (2, 2, -2))]:
        s += quad(*q)
    n = 64
    pts, tris = [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = -2 + 4 * i / n, -2 + 4 * j / n
            y = 1.5 + 0.03 * math.sin(5 * x + 2 * z) + 0.02 * math.cos(7 * z - 3 * x) + 0.01 * math.sin(13 * x + 11 * z)
            pts.append([x, y, z])
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            tris += [(a, a + 1, a + n + 2), (a, a + n + 2, a + n + 1)]
    s += 'AttributeBegin\n  MediumInterface "water" ""\n  Material "dielectric" "float eta" [ 1.33 ]\n'
    s += "  " + mesh(pts, outward(pts, tris, None)) + "AttributeEnd\n"
    return volpath(s)


def volpath(scene):
    """pbrt-v4's "path" ignores media (and its shadow rays stop at interface surfaces): scenes
    with media name "volpath", which bpm renders with its path tracer."""
    return scene.replace('Integrator "path"', 'Integrator "volpath"')


def plume_density(nx, ny, nz):
    """A rising plume: a column that widens and thins with height, swirled by a few sines, in a
    grid of nx x ny x nz samples (x fastest, as uniformgrid reads them)."""
    values = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                x, y, z = (i + 0.5) / nx - 0.5, (j + 0.5) / ny, (k + 0.5) / nz - 0.5
                cx = 0.12 * math.sin(5.0 * y) * y
                cz = 0.10 * math.cos(4.0 * y + 1.0) * y
                width = 0.08 + 0.22 * y
                r2 = ((x - cx) ** 2 + (z - cz) ** 2) / (width * width)
                swirl = 1 + 0.5 * math.sin(9 * x + 7 * y) * math.sin(8 * z - 5 * y)
                d = math.exp(-r2) * (1.2 - 0.8 * y) * swirl
                values.append(max(0.0, d))
    return values


def smoke():
    s = header("# A plume of smoke over a floor: a uniformgrid medium (24 x 32 x 24 samples, denser low\n"
               "# down, swirled) inside an interface box, lit by a spot light from the side and a dim\n"
               "# sky panel. The camera stands in clear air.\n",
               "0 1.2 -3.2   0 0.9 0   0 1 0", 45, (192, 192), 8, "smoke")
    s = volpath(s)
    s += ('LightSource "spot" "point3 from" [ -2.2 2.4 -0.8 ] "point3 to" [ 0 0.8 0 ]\n'
          '    "float coneangle" [ 20 ] "float conedeltaangle" [ 4 ] "blackbody I" [ 4500 ]\n'
          '    "float scale" [ 25 ]\n')
    s += ('AttributeBegin\n  AreaLightSource "diffuse" "rgb L" [ 0.25 0.3 0.4 ]\n'
          '  Material "diffuse" "rgb reflectance" [ 0 0 0 ]\n'
          '  ' + quad((2, 3, -2), (2, 3, 2), (-2, 3, 2), (-2, 3, -2)) + 'AttributeEnd\n')
    s += 'Material "diffuse" "rgb reflectance" [ 0.6 0.6 0.55 ]\n'
    s += quad((-3, 0, -4), (-3, 0, 3), (3, 0, 3), (3, 0, -4))
    s += quad((-3, 0, 2), (-3, 3, 2), (3, 3, 2), (3, 0, 2))
    nx, ny, nz = 24, 32, 24
    dens = plume_density(nx, ny, nz)
    s += ('AttributeBegin\n  Translate -0.6 0 -0.6\n  Scale 1.2 2 1.2\n'
          '  MakeNamedMedium "smoke" "string type" "uniformgrid" "integer nx" [ %d ]\n'
          '    "integer ny" [ %d ] "integer nz" [ %d ] "rgb sigma_a" [ 0.4 0.4 0.4 ]\n'
          '    "rgb sigma_s" [ 3 3 3 ] "float g" [ 0.2 ]\n    "float density" [\n' % (nx, ny, nz))
    for start in range(0, len(dens), 16):
        s += '      ' + ' '.join('%.4g' % v for v in dens[start:start + 16]) + '\n'
    s += '    ]\nAttributeEnd\n'
    s += ('AttributeBegin\n  MediumInterface "smoke" ""\n  Material "interface"\n  '
          + box(-0.6, 0.001, -0.6, 0.6, 2, 0.6) + 'AttributeEnd\n')
    return s


def shelf_room():
    s = header("# A living room lit by one small bright sphere: thin open shelves with books on the back\n"
               "# wall, a sofa, a low table, red-tinted glass objects (glass around an absorbing medium).\n"
               "# Thin geometry against walls and small gaps under furniture, lit mostly indirectly.\n",
               "1.0 1.35 -0.2   -1.0 1.15 2.5   0 1 0", 50, (320, 180), 12, "shelf-room")
    s += 'MakeNamedMedium "red" "string type" "homogeneous" "rgb sigma_a" [ 0.4 6 5 ]\n'
    s += '    "rgb sigma_s" [ 0 0 0 ]\n'
    s += 'Material "diffuse" "rgb reflectance" [ 0.72 0.7 0.66 ]\n'
    s += room_walls(-3, 3, 2.7, -2.5, 2.5)
    s += 'Material "diffuse" "rgb reflectance" [ 0.38 0.26 0.16 ]\n'
    s += room_floor(-3, 3, -2.5, 2.5)
    # Open shelves on the back wall: four boards 2.5 cm thick and 28 cm deep between two thin sides.
    s += 'Material "diffuse" "rgb reflectance" [ 0.62 0.6 0.56 ]\n'
    for y in (1.0, 1.38, 1.76, 2.14):
        s += box(-2.6, y, 2.22, -1.2, y + 0.025, 2.5)
    s += box(-2.62, 1.0, 2.22, -2.6, 2.165, 2.5) + box(-1.2, 1.0, 2.22, -1.18, 2.165, 2.5)
    # Books standing on the boards.
    colours = [(0.5, 0.15, 0.1), (0.15, 0.25, 0.45), (0.55, 0.5, 0.3), (0.2, 0.35, 0.2)]
    for i, y in enumerate((1.025, 1.405, 1.785)):
        x = -2.55 + 0.17 * i
        for j in range(5 - i):
            c = colours[(i + j) % 4]
            s += 'Material "diffuse" "rgb reflectance" [ %g %g %g ]\n' % c
            h = 0.22 + 0.03 * ((i + 2 * j) % 3)
            s += box(x, y, 2.27, x + 0.045, y + h, 2.47)
            x += 0.055
    # A sofa against the right half of the back wall, and a low table in front of it.
    s += 'Material "diffuse" "rgb reflectance" [ 0.3 0.3 0.38 ]\n'
    s += box(0.2, 0.05, 1.55, 2.4, 0.45, 2.35) + box(0.2, 0.45, 2.1, 2.4, 0.9, 2.4)
    s += box(0.05, 0.05, 1.55, 0.2, 0.62, 2.4) + box(2.4, 0.05, 1.55, 2.55, 0.62, 2.4)
    s += 'Material "diffuse" "rgb reflectance" [ 0.45 0.32 0.2 ]\n'
    s += box(0.3, 0.36, 0.35, 1.7, 0.4, 1.05)
    for x, z in ((0.35, 0.4), (1.62, 0.4), (0.35, 0.97), (1.62, 0.97)):
        s += box(x, 0, z, x + 0.03, 0.36, z + 0.03)
    # Red-tinted glass: a sphere and an upright ellipsoid on the table, a sphere on a shelf.
    for t, sc, r in (("0.7 0.52 0.7", "1 1 1", 0.12), ("1.25 0.56 0.8", "1 1.6 1", 0.1),
                     ("-1.6 1.84 2.36", "1 1 1", 0.06)):
        s += ('AttributeBegin\n  Material "dielectric" "float eta" [ 1.5 ]\n'
              '  MediumInterface "red" ""\n  Translate %s\n  Scale %s\n'
              '  Shape "sphere" "float radius" [ %g ]\nAttributeEnd\n' % (t, sc, r))
    # The light: one small bright sphere under the ceiling.
    s += ('AttributeBegin\n  Translate 0.3 2.25 0.4\n'
          '  AreaLightSource "diffuse" "blackbody L" [ 3000 ] "float scale" [ 4000 ]\n'
          '  Shape "sphere" "float radius" [ 0.04 ]\nAttributeEnd\n')
    return s


def kitchen():
    s = header("# A kitchen lit by a window (a bright panel in the left wall) and three strip lights under\n"
               "# its wall cabinets: base cabinets with a counter, wall cabinets, a table with two\n"
               "# chairs, glasses and a bottle on the counter and the table.\n",
               "2.2 1.55 -1.9   -0.4 0.95 1.2   0 1 0", 62, (320, 180), 12, "kitchen")
    s += 'Material "diffuse" "rgb reflectance" [ 0.75 0.74 0.7 ]\n'
    s += room_walls(-2.5, 2.5, 2.6, -2.5, 2)
    s += 'Material "diffuse" "rgb reflectance" [ 0.42 0.4 0.38 ]\n'
    s += room_floor(-2.5, 2.5, -2.5, 2)
    # Base cabinets along the back wall, a counter on them, wall cabinets above.
    s += 'Material "diffuse" "rgb reflectance" [ 0.55 0.5 0.42 ]\n'
    for x in (-2.3, -1.5, -0.7, 0.1, 0.9):
        s += box(x, 0.1, 1.4, x + 0.78, 0.86, 2)
        s += box(x, 1.5, 1.65, x + 0.78, 2.3, 2)
    s += 'Material "coateddiffuse" "rgb reflectance" [ 0.2 0.2 0.22 ] "float roughness" [ 0.2 ]\n'
    s += box(-2.35, 0.86, 1.35, 1.72, 0.9, 2)
    # Three strip lights under the wall cabinets.
    for x in (-2.2, -1.0, 0.2):
        s += ('AttributeBegin\n  AreaLightSource "diffuse" "blackbody L" [ 3500 ] "float scale" [ 30 ]\n'
              '  ' + quad((x, 1.49, 1.72), (x + 0.9, 1.49, 1.72), (x + 0.9, 1.49, 1.76), (x, 1.49, 1.76)) +
              'AttributeEnd\n')
    # The window: a bright panel in the left wall, facing into the room.
    s += ('AttributeBegin\n  AreaLightSource "diffuse" "blackbody L" [ 6500 ] "float scale" [ 12 ]\n'
          '  ' + quad((-2.49, 0.9, -1.2), (-2.49, 2.2, -1.2), (-2.49, 2.2, 0.4), (-2.49, 0.9, 0.4)) +
          'AttributeEnd\n')
    # A table with two chairs.
    s += 'Material "diffuse" "rgb reflectance" [ 0.5 0.36 0.22 ]\n'
    s += box(-1.1, 0.72, -0.8, 0.3, 0.76, 0.1)
    for x, z in ((-1.05, -0.75), (0.22, -0.75), (-1.05, 0.02), (0.22, 0.02)):
        s += box(x, 0, z, x + 0.04, 0.72, z + 0.04)
    for x0 in (-0.9, -0.1):
        s += box(x0, 0.44, -1.3, x0 + 0.42, 0.47, -0.9) + box(x0, 0.47, -1.33, x0 + 0.42, 0.95, -1.3)
        for x, z in ((x0, -1.3), (x0 + 0.39, -1.3), (x0, -0.93), (x0 + 0.39, -0.93)):
            s += box(x, 0, z, x + 0.03, 0.44, z + 0.03)
    # Glass: tumblers (open cylinders of glass with a disk base), a bottle, a bowl.
    glass = '  Material "dielectric" "float eta" [ 1.5 ]\n'
    for x, y, z in ((-0.7, 0.76, -0.4), (-0.4, 0.76, -0.2), (-1.2, 0.9, 1.6), (-0.9, 0.9, 1.55)):
        s += ('AttributeBegin\n' + glass + '  Translate %g %g %g\n  Rotate -90 1 0 0\n'
              '  Shape "cylinder" "float radius" [ 0.035 ] "float zmin" [ 0 ] "float zmax" [ 0.11 ]\n'
              '  Shape "disk" "float radius" [ 0.035 ]\nAttributeEnd\n' % (x, y, z))
    s += ('AttributeBegin\n' + glass + '  Translate 0.3 0.9 1.62\n  Rotate -90 1 0 0\n'
          '  Shape "cylinder" "float radius" [ 0.045 ] "float zmin" [ 0 ] "float zmax" [ 0.24 ]\n'
          '  Shape "disk" "float radius" [ 0.045 ]\n  Translate 0 0 0.24\n'
          '  Shape "disk" "float radius" [ 0.045 ]\nAttributeEnd\n')
    s += ('AttributeBegin\n' + glass + '  Translate -0.2 0.86 -0.5\n  Scale 1 0.5 1\n'
          '  Shape "sphere" "float radius" [ 0.16 ]\nAttributeEnd\n')
    return s


def main():
    for name, text in [("spot-facets", spot_facets()), ("water-box", water_box()),
                       ("lamp-room", lamp_room()), ("spot-lens-fog", spot_lens_fog()),
                       ("underwater", underwater()), ("smoke", smoke()),
                       ("shelf-room", shelf_room()), ("kitchen", kitchen())]:
        with open(os.path.join(OUT, name + ".pbrt"), "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
