#!/usr/bin/python3
"""Generates the lvox showcase scene geometry: a Sponza-style atrium.

Writes assets/atrium.obj and assets/atrium.mtl next to this script. Python 3 standard
library only, deterministic (byte-identical output on every run), about a second.

Layout (metres, Y up, the long axis is x):
  * an open courtyard of 30 x 12 m (column lines at x = +-15, z = +-6), no roof over it;
  * two storeys of arcades on the four sides: ground floor with round arches (3 m bays)
    on cylindrical columns with square plinths and capitals, an upper gallery with
    smaller arches (1.5 m bays) and a balustrade, a floor slab between the storeys;
  * galleries 3 m deep, closed by outer walls and covered by a roof slab;
  * coloured fabric banners hanging from the upper balustrade in front of the ground
    arches.
Every piece overlaps its neighbours by a centimetre or more, so that no light leaks
through cracks (lvox treats surfaces as two-sided, so winding does not matter for it;
the faces are still wound consistently where it is cheap).
"""

import math
import os

# ---------------------------------------------------------------------------------------
# Dimensions. Everything else is derived from these.

HALF_X = 15.0  # column line of the short sides (x = +-15)
HALF_Z = 6.0  # column line of the long sides (z = +-6)
GALLERY_DEPTH = 3.0  # from the column line to the inner face of the outer wall
OUTER_WALL = 0.4  # thickness of the outer walls
BAY = 3.0  # ground-floor bay (column spacing)
UPPER_BAY = 1.5  # upper-gallery bay: two upper arches per ground arch

# Ground storey.
GROUND_SPRING = 3.65  # top of the ground capitals, where the arches spring
GROUND_TOP = 5.45  # top of the ground arcade wall (overlaps the slab)
GROUND_WALL_HALF = 0.30  # half thickness of the ground arcade wall
GROUND_RADIUS = 0.30  # shaft radius
GROUND_ABACUS = 0.42  # half width of the square capital and plinth

# Floor slab between the storeys.
SLAB_BOTTOM = 5.40
SLAB_TOP = 5.75
SLAB_LEDGE = 0.45  # how far the slab projects into the courtyard from the column line

# Upper storey.
UPPER_SPRING = 8.10
UPPER_TOP = 9.35
UPPER_WALL_HALF = 0.20
UPPER_RADIUS = 0.15
UPPER_ABACUS = 0.25
RAIL_TOP = 6.65  # top of the balustrade on the upper gallery
RAIL_HALF = 0.12

# Roof of the galleries and attic wall above the upper arcade.
ROOF_BOTTOM = 9.30
ROOF_TOP = 9.60
ATTIC_TOP = 10.85
CORNICE_BOTTOM = 10.80
CORNICE_TOP = 11.00

TILE = 1.5  # courtyard paving

# Tessellation.
GROUND_SEGMENTS = 24  # around a ground column
UPPER_SEGMENTS = 16  # around an upper column
GROUND_ARCH_SEGMENTS = 24  # along a ground arch
UPPER_ARCH_SEGMENTS = 16  # along an upper arch
BANNER_COLUMNS = 14
BANNER_ROWS = 30

MATERIALS = [
    # name, Kd (linear albedo)
    ("stone", (0.70, 0.66, 0.60)),
    ("stone_column", (0.74, 0.71, 0.65)),
    ("stone_trim", (0.64, 0.61, 0.56)),
    ("plaster", (0.68, 0.62, 0.55)),
    ("floor_light", (0.56, 0.53, 0.49)),
    ("floor_dark", (0.47, 0.44, 0.41)),
    ("floor_gallery", (0.52, 0.48, 0.44)),
    ("banner_red", (0.70, 0.12, 0.10)),
    ("banner_green", (0.12, 0.70, 0.15)),
    ("banner_blue", (0.12, 0.15, 0.70)),
    ("banner_yellow", (0.70, 0.60, 0.12)),
]


# ---------------------------------------------------------------------------------------
# Mesh writer: named groups, one material each; vertices deduplicated on their printed
# value, so touching pieces share exact vertices and the output is deterministic.


def fmt(x):
    s = "%.4f" % x
    if s == "-0.0000":
        s = "0.0000"
    return s


class Mesh:
    def __init__(self):
        self.vertex_index = {}
        self.vertices = []
        self.groups = []  # [name, material, [faces]]

    def group(self, name, material):
        self.groups.append([name, material, []])

    def vertex(self, p):
        key = "%s %s %s" % (fmt(p[0]), fmt(p[1]), fmt(p[2]))
        index = self.vertex_index.get(key)
        if index is None:
            self.vertices.append(key)
            index = len(self.vertices)
            self.vertex_index[key] = index
        return index

    def tri(self, a, b, c):
        ia, ib, ic = self.vertex(a), self.vertex(b), self.vertex(c)
        if ia != ib and ib != ic and ia != ic:  # drop triangles collapsed by rounding
            self.groups[-1][2].append((ia, ib, ic))

    def quad(self, a, b, c, d):
        self.tri(a, b, c)
        self.tri(a, c, d)

    def box(self, lo, hi):
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        p = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
             (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
        for a, b, c, d in ((0, 3, 2, 1), (4, 5, 6, 7), (0, 4, 7, 3),
                           (1, 2, 6, 5), (0, 1, 5, 4), (3, 7, 6, 2)):
            self.quad(p[a], p[b], p[c], p[d])

    def triangle_count(self):
        return sum(len(g[2]) for g in self.groups)

    def write(self, obj_path, mtl_path):
        mtl_name = os.path.basename(mtl_path)
        lines = ["# Sponza-style atrium generated by make_atrium.py (lvox). Y up, metres.",
                 "# %d vertices, %d triangles" % (len(self.vertices), self.triangle_count()),
                 "mtllib %s" % mtl_name]
        lines += ["v " + v for v in self.vertices]
        for name, material, faces in self.groups:
            if not faces:
                continue
            lines.append("g %s" % name)
            lines.append("usemtl %s" % material)
            lines += ["f %d %d %d" % f for f in faces]
        with open(obj_path, "w", newline="\n") as f:
            f.write("\n".join(lines) + "\n")
        mtl = ["# Materials of atrium.obj (Lambertian; lvox reads Kd as the albedo)."]
        for name, kd in MATERIALS:
            mtl += ["", "newmtl %s" % name, "Ka 0 0 0",
                    "Kd %.3f %.3f %.3f" % kd, "Ks 0 0 0", "illum 1"]
        with open(mtl_path, "w", newline="\n") as f:
            f.write("\n".join(mtl) + "\n")


# ---------------------------------------------------------------------------------------
# Sides of the courtyard. A side maps local (u along the arcade, v up, w across it with
# w < 0 on the courtyard side) to world space. All sides are axis aligned.


class Side:
    def __init__(self, name, axis, line, outward, half_length):
        self.name = name
        self.axis = axis  # "x": the arcade runs along x (long sides), "z": along z
        self.line = line  # coordinate of the column line on the other axis
        self.outward = outward  # +1 or -1: direction of +w on the other axis
        self.half_length = half_length  # the columns at u = +-half_length are corners

    def point(self, u, v, w):
        across = self.line + self.outward * w
        if self.axis == "x":
            return (u, v, across)
        return (across, v, u)

    def box(self, mesh, u0, u1, v0, v1, w0, w1):
        a = self.point(u0, v0, w0)
        b = self.point(u1, v1, w1)
        mesh.box(tuple(min(a[i], b[i]) for i in range(3)),
                 tuple(max(a[i], b[i]) for i in range(3)))


SIDES = [
    Side("south", "x", -HALF_Z, -1.0, HALF_X),
    Side("north", "x", HALF_Z, 1.0, HALF_X),
    Side("west", "z", -HALF_X, -1.0, HALF_Z),
    Side("east", "z", HALF_X, 1.0, HALF_Z),
]


def column_positions(side, spacing, include_corners):
    n = int(round(2 * side.half_length / spacing))
    us = [-side.half_length + i * spacing for i in range(n + 1)]
    return us if include_corners else us[1:-1]


# ---------------------------------------------------------------------------------------
# Columns: a square plinth, a turned profile (torus base, shaft with entasis, necking,
# echinus) and a square abacus.


def column_profile(radius, y0, y1):
    """(r, y) points of the turned part of a column from y0 (floor) to y1 (spring)."""
    k = radius / 0.30  # the profile is designed for a 0.30 m shaft
    plinth_top = y0 + 0.25 * k
    abacus_bottom = y1 - 0.16 * k
    pts = [(0.41, plinth_top - 0.01 * k), (0.42, plinth_top + 0.04 * k),
           (0.40, plinth_top + 0.08 * k), (0.34, plinth_top + 0.11 * k),
           (0.33, plinth_top + 0.15 * k), (0.31, plinth_top + 0.19 * k)]
    profile = [(r * k, y) for r, y in pts]
    shaft_bottom = plinth_top + 0.27 * k
    shaft_top = abacus_bottom - 0.30 * k
    for i in range(4):  # entasis: the shaft narrows by 10 % towards the top
        t = i / 3.0
        profile.append((radius * (1.0 - 0.10 * t * t), shaft_bottom + t * (shaft_top - shaft_bottom)))
    top = [(0.29, 0.28), (0.29, 0.22), (0.27, 0.20), (0.30, 0.14), (0.36, 0.07), (0.41, 0.0)]
    profile += [(r * k, abacus_bottom - dy * k) for r, dy in top]
    return profile, plinth_top, abacus_bottom


def column(mesh, centre, y0, y1, radius, half_square, segments):
    cx, cz = centre
    profile, plinth_top, abacus_bottom = column_profile(radius, y0, y1)
    mesh.box((cx - half_square - 0.03, y0, cz - half_square - 0.03),
             (cx + half_square + 0.03, plinth_top, cz + half_square + 0.03))
    rings = []
    for r, y in profile:
        ring = []
        for j in range(segments):
            phi = 2.0 * math.pi * j / segments
            ring.append((cx + r * math.cos(phi), y, cz + r * math.sin(phi)))
        rings.append(ring)
    for lower, upper in zip(rings, rings[1:]):
        for j in range(segments):
            jn = (j + 1) % segments
            mesh.quad(lower[j], upper[j], upper[jn], lower[jn])
    # The abacus reaches 1 cm above the spring line so the arcade wall sits into it.
    mesh.box((cx - half_square, abacus_bottom - 0.01, cz - half_square),
             (cx + half_square, y1 + 0.01, cz + half_square))


# ---------------------------------------------------------------------------------------
# Arcade walls: one panel per bay, a slab of the wall between two column centres with a
# semicircular opening. Each face is a strip of quads between the arch and the panel's
# rectangle, matched by angle from the arch centre; the soffit joins the two faces.


def arch_angles(half_width, height, segments):
    corner = math.atan2(height, half_width)
    angles = {round(math.pi * (1.0 - i / segments), 12) for i in range(segments + 1)}
    angles.add(round(math.pi - corner, 12))
    angles.add(round(corner, 12))
    return sorted(angles, reverse=True)  # from pi (left springing) to 0 (right)


def arcade_panel(mesh, side, c0, c1, spring, top, radius, half_thickness, segments):
    centre = 0.5 * (c0 + c1)
    half_width = 0.5 * (c1 - c0)
    height = top - spring
    inner, outer = [], []
    for theta in arch_angles(half_width, height, segments):
        c, s = math.cos(theta), math.sin(theta)
        inner.append((centre + radius * c, spring + radius * s))
        reach = min(half_width / abs(c) if abs(c) > 1e-12 else math.inf,
                    height / s if s > 1e-12 else math.inf)
        outer.append((centre + reach * c, spring + reach * s))
    for w in (-half_thickness, half_thickness):
        for i in range(len(inner) - 1):
            quad = [inner[i], outer[i], outer[i + 1], inner[i + 1]]
            if w > 0:
                quad.reverse()
            mesh.quad(*[side.point(u, v, w) for u, v in quad])
    for i in range(len(inner) - 1):
        (ua, va), (ub, vb) = inner[i], inner[i + 1]
        mesh.quad(side.point(ua, va, -half_thickness), side.point(ub, vb, -half_thickness),
                  side.point(ub, vb, half_thickness), side.point(ua, va, half_thickness))


def arcade(mesh, side, spacing, spring, top, abacus, half_thickness, segments):
    us = column_positions(side, spacing, True)
    radius = 0.5 * spacing - abacus
    for c0, c1 in zip(us, us[1:]):
        arcade_panel(mesh, side, c0, c1, spring, top, radius, half_thickness, segments)


# ---------------------------------------------------------------------------------------
# Banners: a cloth strip hanging from the balustrade, draped over the slab ledge, with
# vertical folds that deepen towards the bottom and a pointed (pennant) lower edge.


def smoothstep(e0, e1, x):
    t = min(1.0, max(0.0, (x - e0) / (e1 - e0)))
    return t * t * (3.0 - 2.0 * t)


def banner(mesh, side, u_centre, width, top, length, tip, phase):
    grid = []
    for row in range(BANNER_ROWS + 1):
        t = row / BANNER_ROWS
        line = []
        for col in range(BANNER_COLUMNS + 1):
            s = col / BANNER_COLUMNS
            u = u_centre + (s - 0.5) * width * (1.0 - 0.05 * t)
            v = top - t * (length + tip * (1.0 - abs(2.0 * s - 1.0)))
            drape = -0.20 - 0.40 * smoothstep(0.0, 0.3, t)
            folds = 0.05 * math.sin(2.0 * math.pi * 2.5 * s + phase) * (0.3 + 0.7 * t)
            line.append(side.point(u, v, drape + folds))
        grid.append(line)
    for row in range(BANNER_ROWS):
        for col in range(BANNER_COLUMNS):
            mesh.quad(grid[row][col], grid[row + 1][col], grid[row + 1][col + 1],
                      grid[row][col + 1])


# ---------------------------------------------------------------------------------------
# The building.


def floors(mesh):
    mesh.group("floor_courtyard", "floor_light")
    nx, nz = int(round(2 * HALF_X / TILE)), int(round(2 * HALF_Z / TILE))
    dark = []
    for i in range(nx):
        for k in range(nz):
            x0, z0 = -HALF_X + i * TILE, -HALF_Z + k * TILE
            tile = [(x0, 0.0, z0), (x0, 0.0, z0 + TILE), (x0 + TILE, 0.0, z0 + TILE),
                    (x0 + TILE, 0.0, z0)]
            if (i + k) % 2:
                dark.append(tile)
            else:
                mesh.quad(*tile)
    mesh.group("floor_courtyard_dark", "floor_dark")
    for tile in dark:
        mesh.quad(*tile)
    mesh.group("floor_gallery", "floor_gallery")
    ox, oz = HALF_X + GALLERY_DEPTH + OUTER_WALL, HALF_Z + GALLERY_DEPTH + OUTER_WALL
    for x0, x1, z0, z1 in ((-ox, ox, HALF_Z, oz), (-ox, ox, -oz, -HALF_Z),
                           (HALF_X, ox, -HALF_Z, HALF_Z), (-ox, -HALF_X, -HALF_Z, HALF_Z)):
        mesh.quad((x0, 0.0, z0), (x0, 0.0, z1), (x1, 0.0, z1), (x1, 0.0, z0))


def outer_walls(mesh):
    mesh.group("outer_walls", "plaster")
    gx, gz = HALF_X + GALLERY_DEPTH, HALF_Z + GALLERY_DEPTH
    t = OUTER_WALL
    mesh.box((-gx - t, 0.0, gz), (gx + t, CORNICE_TOP, gz + t))
    mesh.box((-gx - t, 0.0, -gz - t), (gx + t, CORNICE_TOP, -gz))
    mesh.box((gx, 0.0, -gz), (gx + t, CORNICE_TOP, gz))
    mesh.box((-gx - t, 0.0, -gz), (-gx, CORNICE_TOP, gz))


def ring_boxes(mesh, y0, y1, inner_w):
    """Slabs covering the gallery ring, from w = inner_w on each column line to the
    outer walls (overlapping them and each other at the corners)."""
    for side in SIDES:
        far = GALLERY_DEPTH + 0.5 * OUTER_WALL
        if side.axis == "x":
            span = HALF_X + GALLERY_DEPTH + 0.5 * OUTER_WALL
        else:
            span = HALF_Z
        side.box(mesh, -span, span, y0, y1, inner_w, far)


def ground_storey(mesh):
    mesh.group("columns_ground", "stone_column")
    for side in SIDES:
        for u in column_positions(side, BAY, side.axis == "x"):
            p = side.point(u, 0.0, 0.0)
            column(mesh, (p[0], p[2]), 0.0, GROUND_SPRING, GROUND_RADIUS, GROUND_ABACUS,
                   GROUND_SEGMENTS)
    mesh.group("arcade_ground", "stone")
    for side in SIDES:
        arcade(mesh, side, BAY, GROUND_SPRING, GROUND_TOP, GROUND_ABACUS, GROUND_WALL_HALF,
               GROUND_ARCH_SEGMENTS)
        # Corner piers fill the quarter the two arcade walls leave open at each corner.
        for end in (-1.0, 1.0) if side.axis == "x" else ():
            u = end * side.half_length
            side.box(mesh, u - GROUND_WALL_HALF, u + GROUND_WALL_HALF, GROUND_SPRING,
                     GROUND_TOP, -GROUND_WALL_HALF, GROUND_WALL_HALF)
    mesh.group("slab", "stone_trim")
    ring_boxes(mesh, SLAB_BOTTOM, SLAB_TOP, -SLAB_LEDGE)


def upper_storey(mesh):
    mesh.group("columns_upper", "stone_column")
    for side in SIDES:
        for u in column_positions(side, UPPER_BAY, side.axis == "x"):
            p = side.point(u, 0.0, 0.0)
            column(mesh, (p[0], p[2]), SLAB_TOP, UPPER_SPRING, UPPER_RADIUS, UPPER_ABACUS,
                   UPPER_SEGMENTS)
    mesh.group("arcade_upper", "stone")
    for side in SIDES:
        arcade(mesh, side, UPPER_BAY, UPPER_SPRING, UPPER_TOP, UPPER_ABACUS, UPPER_WALL_HALF,
               UPPER_ARCH_SEGMENTS)
        for end in (-1.0, 1.0):
            u = end * side.half_length
            side.box(mesh, u - UPPER_WALL_HALF, u + UPPER_WALL_HALF, UPPER_SPRING, UPPER_TOP,
                     -UPPER_WALL_HALF, UPPER_WALL_HALF)
    mesh.group("balustrade", "stone_trim")
    for side in SIDES:
        reach = side.half_length + RAIL_HALF + 0.05
        side.box(mesh, -reach, reach, SLAB_TOP - 0.01, RAIL_TOP - 0.10, -RAIL_HALF, RAIL_HALF)
        side.box(mesh, -reach - 0.05, reach + 0.05, RAIL_TOP - 0.11, RAIL_TOP,
                 -RAIL_HALF - 0.05, RAIL_HALF + 0.05)


def roof(mesh):
    mesh.group("gallery_roof", "stone_trim")
    ring_boxes(mesh, ROOF_BOTTOM, ROOF_TOP, -UPPER_WALL_HALF)
    mesh.group("attic", "stone")
    for side in SIDES:
        reach = side.half_length + 0.25
        side.box(mesh, -reach, reach, ROOF_BOTTOM, ATTIC_TOP, -0.25, 0.25)
    mesh.group("cornice", "stone_trim")
    ring_boxes(mesh, CORNICE_BOTTOM, CORNICE_TOP, -0.45)


def banners(mesh):
    # (side, ground bay index from the low-u end, colour). Chosen so that the default
    # camera (west end, looking east) sees every colour on both long sides and no two
    # facing banners match; the west side, behind that camera, gets none.
    placements = [
        ("north", 2, "banner_yellow"), ("north", 4, "banner_red"),
        ("north", 6, "banner_blue"), ("north", 8, "banner_green"),
        ("south", 2, "banner_blue"), ("south", 4, "banner_green"),
        ("south", 6, "banner_yellow"), ("south", 8, "banner_red"),
        ("east", 1, "banner_red"), ("east", 2, "banner_blue"),
    ]
    by_name = {s.name: s for s in SIDES}
    for n, (name, bay, colour) in enumerate(placements):
        side = by_name[name]
        u = -side.half_length + (bay + 0.5) * BAY
        mesh.group("banner_%02d_%s" % (n, colour[len("banner_"):]), colour)
        banner(mesh, side, u, 1.3, RAIL_TOP - 0.03, 2.95, 0.35, 0.7 * n)


def build():
    mesh = Mesh()
    floors(mesh)
    outer_walls(mesh)
    ground_storey(mesh)
    upper_storey(mesh)
    roof(mesh)
    banners(mesh)
    return mesh


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    mesh = build()
    mesh.write(os.path.join(here, "atrium.obj"), os.path.join(here, "atrium.mtl"))
    print("atrium.obj: %d vertices, %d triangles" % (len(mesh.vertices), mesh.triangle_count()))


if __name__ == "__main__":
    main()
