#!/usr/bin/env python3
"""Generates a game-like glTF 2.0 level for hemibake: rooms on double-loaded corridors, doorways, windows open to
the sky, pillars, stairs up to platforms, furniture and shelves, emissive ceiling panels, a sun and a camera.

    python3 examples/generate_level.py --seed 1 --triangles 10000 -o examples/level_small.gltf

Deterministic: the same seed and triangle target give byte-identical files (Python's own `random`, no
dictionaries iterated in an unspecified order, fixed float formatting through `struct`).

Geometry is made for a radiosity baker (CONVENTIONS.md frame: metres, +Y up):
* every solid is a closed, outward-facing mesh (walls and stairs are 2-D cell grids extruded to a thickness,
  so an opening is a hole through a closed solid, not two overlapping boxes);
* no two faces are coplanar and overlapping: parts that meet interpenetrate by a few centimetres instead of
  touching, with different depths per kind (x-walls, z-walls, pillars, props), so hidden faces end up inside
  solids and visible ones never z-fight;
* reflectances 0.2-0.8, emission through emissiveFactor × KHR_materials_emissive_strength.
Standard library only, so it runs on a stock Debian python3.

--clean builds the same layout (rooms, corridors, doorways, windows) with parts that MEET WITHOUT OVERLAPPING: the
level on which a baker's convergence can be judged apart from leaks through interpenetrating geometry (an element
of a floor slab that runs under a wall is lit on one side of the wall and dark on the other). Each room and corridor
is the inside of a box (inward faces: a floor and a ceiling that end exactly at the wall faces, four walls cut
around the openings); each doorway or window is a tunnel of four reveal faces through the wall thickness; the
building's outside is outward walls (windows cut), roof and underside. Props stand exactly on the floor with
their bottom faces dropped and the floor cut under them (and likewise boards under books, table tops over legs,
crates under crates); pillars reach floor and ceiling, both cut around them; light panels are single downward
quads 1 cm below the ceiling. No face passes under or through a solid, no two faces share area, faces touch only
along edges (T-vertices allowed); every surface but the panels is closed. The first corridor has no window and
no panel (lit only through its doorways); half the rooms have panels. Clean levels are deterministic too.

    python3 examples/generate_level.py --clean --seed 1 --triangles 8000 -o examples/level_clean.gltf
"""
import argparse
import json
import math
import os
import random
import struct

WALL_T = 0.2          # wall thickness, metres
TILE_GAP = 10.0       # between copies of the level (--tiles), metres: the sun's shadows (2.4 m from 3.2 m) stay apart
HEIGHT = 3.0          # storey height (floor top to ceiling underside)
CORRIDOR_W = 2.4
# Penetration depths into the floor / ceiling slabs, different per kind so hidden faces never coincide.
PEN_XWALL, PEN_ZWALL, PEN_PILLAR, PEN_PROP = 0.05, 0.03, 0.04, 0.01

MATERIALS = [
    # name, baseColor (linear), emissive factor, emissive strength
    ("floor", (0.45, 0.42, 0.38), None, None),
    ("wall", (0.70, 0.68, 0.62), None, None),
    ("ceiling", (0.75, 0.75, 0.72), None, None),
    ("concrete", (0.55, 0.55, 0.55), None, None),
    ("wood", (0.50, 0.35, 0.20), None, None),
    ("crate", (0.60, 0.45, 0.25), None, None),
    ("book_red", (0.60, 0.20, 0.20), None, None),
    ("book_blue", (0.22, 0.30, 0.60), None, None),
    ("book_green", (0.25, 0.55, 0.30), None, None),
    ("panel", (0.80, 0.80, 0.80), (1.0, 0.95, 0.85), 12.0),
]
MAT = {m[0]: i for i, m in enumerate(MATERIALS)}


class MeshBuilder:
    """Flat-shaded triangles grouped by material; every face gets its own vertices and normal."""

    def __init__(self):
        self.groups = {}  # material index -> ([positions], [normals], [indices]); insertion-ordered
        self.triangles = 0

    def quad(self, mat, p, outward):
        """p: four corners in order around the quad; flipped if needed so the face looks along `outward`."""
        n = _normalize(_cross(_sub(p[1], p[0]), _sub(p[2], p[0])))
        if _dot(n, outward) < 0:
            p = [p[0], p[3], p[2], p[1]]
            n = (-n[0], -n[1], -n[2])
        self._poly(mat, p, n)

    def _poly(self, mat, p, n):
        pos, nor, idx = self.groups.setdefault(mat, ([], [], []))
        base = len(pos)
        pos.extend(p)
        nor.extend([n] * len(p))
        for k in range(1, len(p) - 1):
            idx.extend((base, base + k, base + k + 1))
            self.triangles += 1

    def box(self, mat, lo, hi):
        grid_solid(self, mat, [lo[0], hi[0]], [lo[1], hi[1]], lambda i, j: True, "x", lo[2], hi[2])

    def cylinder(self, mat, cx, cz, r, y0, y1, segments):
        ring = [(cx + r * math.cos(2 * math.pi * k / segments), cz + r * math.sin(2 * math.pi * k / segments))
                for k in range(segments)]
        for k in range(segments):
            a, b = ring[k], ring[(k + 1) % segments]
            mid = ((a[0] + b[0]) / 2 - cx, 0.0, (a[1] + b[1]) / 2 - cz)
            self.quad(mat, [(a[0], y0, a[1]), (b[0], y0, b[1]), (b[0], y1, b[1]), (a[0], y1, a[1])], mid)
        top = [(x, y1, z) for x, z in ring]
        self._poly(mat, list(reversed(top)), (0.0, 1.0, 0.0))
        bottom = [(x, y0, z) for x, z in ring]
        self._poly(mat, bottom, (0.0, -1.0, 0.0))


def _sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def _dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
def _cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _normalize(a):
    length = math.sqrt(_dot(a, a)) or 1.0
    return (a[0] / length, a[1] / length, a[2] / length)


def grid_solid(mb, mat, us, ys, solid, axis, w0, w1, bottom=True):
    """A 2-D grid of cells (breakpoints `us` along the solid's length, `ys` up) where solid(i, j) says which cells
    are filled, extruded from w0 to w1 across. axis "x": u runs along x and w along z; axis "z": u along z, w
    along x. Emits only the boundary faces, so the result is one closed solid with holes where cells are empty.
    bottom=False drops the faces under the lowest row (a solid standing on a floor that has a hole under it)."""
    def P(u, y, w):
        return (u, y, w) if axis == "x" else (w, y, u)

    def N(du, dy, dw):
        return (du, dy, dw) if axis == "x" else (dw, dy, du)

    nu, ny = len(us) - 1, len(ys) - 1
    filled = lambda i, j: 0 <= i < nu and 0 <= j < ny and solid(i, j)
    for i in range(nu):
        for j in range(ny):
            if not solid(i, j):
                continue
            u0, u1, y0, y1 = us[i], us[i + 1], ys[j], ys[j + 1]
            mb.quad(mat, [P(u0, y0, w1), P(u1, y0, w1), P(u1, y1, w1), P(u0, y1, w1)], N(0, 0, 1))
            mb.quad(mat, [P(u0, y0, w0), P(u1, y0, w0), P(u1, y1, w0), P(u0, y1, w0)], N(0, 0, -1))
            if not filled(i - 1, j):
                mb.quad(mat, [P(u0, y0, w0), P(u0, y1, w0), P(u0, y1, w1), P(u0, y0, w1)], N(-1, 0, 0))
            if not filled(i + 1, j):
                mb.quad(mat, [P(u1, y0, w0), P(u1, y1, w0), P(u1, y1, w1), P(u1, y0, w1)], N(1, 0, 0))
            if not filled(i, j - 1) and (bottom or j > 0):
                mb.quad(mat, [P(u0, y0, w0), P(u1, y0, w0), P(u1, y0, w1), P(u0, y0, w1)], N(0, -1, 0))
            if not filled(i, j + 1):
                mb.quad(mat, [P(u0, y1, w0), P(u1, y1, w0), P(u1, y1, w1), P(u0, y1, w1)], N(0, 1, 0))


def wall(mb, axis, centre, u0, u1, pen, openings):
    """A wall of thickness WALL_T centred on `centre` (z for axis "x", x for axis "z") from u0 to u1, reaching `pen`
    into the floor and ceiling slabs; openings: (ua, ub, ya, yb) holes (doors start at the wall's bottom)."""
    y0, y1 = -pen, HEIGHT + pen
    us = sorted({u0, u1, *[o[0] for o in openings], *[o[1] for o in openings]})
    ys = sorted({y0, y1, *[max(o[2], y0) for o in openings], *[o[3] for o in openings]})

    def solid(i, j):
        cu, cy = (us[i] + us[i + 1]) / 2, (ys[j] + ys[j + 1]) / 2
        return not any(o[0] < cu < o[1] and max(o[2], y0) < cy < o[3] for o in openings)

    grid_solid(mb, MAT["wall"], us, ys, solid, axis, centre - WALL_T / 2, centre + WALL_T / 2)


def stairs(mb, axis, u0, w0, width, steps, rise, run, platform):
    """Steps climbing along +u from u0, then a platform `platform` metres deep, extruded over `width`."""
    us = [u0 + k * run for k in range(steps + 1)] + [u0 + steps * run + platform]
    ys = [-PEN_PROP] + [(k + 1) * rise for k in range(steps)]
    # Column i (step i, the last one the platform) is filled up to step i's height.
    grid_solid(mb, MAT["concrete"], us, ys, lambda i, j: j <= min(i, steps - 1), axis, w0, w0 + width)
    return us[-1] - u0


class Room:
    def __init__(self, x0, x1, z0, z1):
        self.x0, self.x1, self.z0, self.z1 = x0, x1, z0, z1
        self.used = []  # footprints (x0, z0, x1, z1) already taken by props
        self.ceiling = []  # footprints of ceiling panels, which only floor-to-ceiling pillars must avoid

    def free(self, r, gap=0.25, tall=False):
        for q in self.used + (self.ceiling if tall else []):
            if r[0] < q[2] + gap and q[0] < r[2] + gap and r[1] < q[3] + gap and q[1] < r[3] + gap:
                return False
        return True

    def place(self, rng, w, d, margin=0.9, tall=False):
        """A free footprint w × d inside the room, away from the walls (and so from doorways), or None."""
        for _ in range(30):
            if self.x1 - self.x0 - 2 * margin < w or self.z1 - self.z0 - 2 * margin < d:
                return None
            x = rng.uniform(self.x0 + margin, self.x1 - margin - w)
            z = rng.uniform(self.z0 + margin, self.z1 - margin - d)
            r = (x, z, x + w, z + d)
            if self.free(r, tall=tall):
                self.used.append(r)
                return r
        return None


# Props draw their sizes and places the same way in both modes (place_*: None when the room has no space), so a
# seed gives the same floor plan; only how the parts meet differs.
TABLE_H = 0.75


def place_table(rng, room):
    w, d = rng.uniform(1.2, 2.0), rng.uniform(0.7, 1.0)
    return room.place(rng, w, d)


def table_legs(r):
    """The four 7 cm legs of a table over rectangle r, as (x0, x1, z0, z1)."""
    return [(lx, lx + 0.07, lz, lz + 0.07) for lx, lz in (
        (r[0] + 0.05, r[1] + 0.05), (r[2] - 0.12, r[1] + 0.05), (r[0] + 0.05, r[3] - 0.12), (r[2] - 0.12, r[3] - 0.12))]


TOP_CRATE = 0.6  # a crate stacked on another is this × its size


def place_crate(rng, room):
    """(size, rectangle, top) with top the smaller crate's rectangle on it (x0, x1, z0, z1) or None."""
    s = rng.uniform(0.5, 0.9)
    r = room.place(rng, s, s)
    if not r:
        return None
    top = None
    if rng.random() < 0.5:
        t = s * TOP_CRATE
        x, z = r[0] + rng.uniform(0.02, s - t - 0.02), r[1] + rng.uniform(0.02, s - t - 0.02)
        top = (x, x + t, z, z + t)
    return s, r, top


def place_shelf(rng, room):
    return room.place(rng, rng.uniform(1.2, 2.2), 0.4)


def place_pillar(rng, room):
    """(radius, footprint square) or None."""
    rad = rng.uniform(0.2, 0.3)
    r = room.place(rng, 2 * rad, 2 * rad, margin=1.2, tall=True)
    return (rad, r) if r else None


def table(mb, rng, room):
    r = place_table(rng, room)
    if not r:
        return False
    h = TABLE_H
    mb.box(MAT["wood"], (r[0], h - 0.05, r[1]), (r[2], h, r[3]))
    for x0, x1, z0, z1 in table_legs(r):
        mb.box(MAT["wood"], (x0, -PEN_PROP, z0), (x1, h - 0.03, z1))  # legs end inside the top
    return True


def crates(mb, rng, room):
    placed = place_crate(rng, room)
    if not placed:
        return False
    s, r, top = placed
    mb.box(MAT["crate"], (r[0], -PEN_PROP, r[1]), (r[2], s, r[3]))
    if top:  # a smaller crate on top, sunk 1 cm into the lower one
        t = s * TOP_CRATE
        mb.box(MAT["crate"], (top[0], s - 0.01, top[2]), (top[1], s - 0.01 + t, top[3]))
    return True


SHELF_H = 2.0


def shelf(mb, rng, room):
    r = place_shelf(rng, room)
    if not r:
        return False
    h = SHELF_H
    mb.box(MAT["wood"], (r[0], -PEN_PROP, r[1]), (r[0] + 0.04, h, r[3]))
    mb.box(MAT["wood"], (r[2] - 0.04, -PEN_PROP, r[1]), (r[2], h, r[3]))
    boards = 4
    for b in range(boards):
        y = 0.1 + b * (h - 0.2) / (boards - 1)
        # Boards run into the uprights (2 cm each side) rather than touching them.
        mb.box(MAT["wood"], (r[0] + 0.02, y - 0.025, r[1] + 0.01), (r[2] - 0.02, y, r[3] - 0.01))
        if b == boards - 1:
            continue
        x = r[0] + 0.06
        while True:
            bw = rng.uniform(0.03, 0.07)
            if x + bw > r[2] - 0.06:
                break
            bh = rng.uniform(0.18, 0.32)
            bd = rng.uniform(0.22, 0.3)
            mat = MAT[rng.choice(("book_red", "book_blue", "book_green"))]
            mb.box(mat, (x, y - 0.01, r[1] + 0.04), (x + bw, y - 0.01 + bh, r[1] + 0.04 + bd))  # sunk into the board
            x += bw + rng.uniform(0.005, 0.02)
    return True


def pillar(mb, rng, room, segments):
    placed = place_pillar(rng, room)
    if not placed:
        return False
    rad, r = placed
    mb.cylinder(MAT["concrete"], (r[0] + r[2]) / 2, (r[1] + r[3]) / 2, rad, -PEN_PILLAR, HEIGHT + PEN_PILLAR, segments)
    return True


def place_staircase(rng, room):
    """Draws a staircase's size and place (the same draws in both modes); None when the room has no space."""
    steps = rng.randint(5, 8)
    rise, run, width, platform = 0.18, 0.28, rng.uniform(0.9, 1.2), 1.2
    length = steps * run + platform
    r = room.place(rng, length, width, margin=0.6)
    return (steps, rise, run, width, platform, r) if r else None


def staircase(mb, rng, room):
    placed = place_staircase(rng, room)
    if not placed:
        return False
    steps, rise, run, width, platform, r = placed
    stairs(mb, "x", r[0], r[1], width, steps, rise, run, platform)
    return True


def furnish(mb, rng, room, segments, makers, room_left):
    """A room's props, the same draws in both modes: a staircase (60 %), 0–2 pillars, then tables, crates, shelves
    and pillars at random while room_left() (the triangle budget) and until 40 of them found no space."""
    staircase_maker, pillar_maker, table_maker, crates_maker, shelf_maker = makers
    if rng.random() < 0.6:
        staircase_maker(mb, rng, room)
    for _ in range(rng.randint(0, 2)):
        pillar_maker(mb, rng, room, segments)
    choices = (table_maker, crates_maker, crates_maker, shelf_maker, shelf_maker, pillar_maker)
    failures = 0
    while room_left() and failures < 40:
        maker = rng.choice(choices)
        ok = maker(mb, rng, room, segments) if maker is pillar_maker else maker(mb, rng, room)
        failures += 0 if ok else 1


def panel(mb, x, z, w, d):
    # Hangs 5 cm below the ceiling: a floating closed box, no face shared with the slab.
    mb.box(MAT["panel"], (x - w / 2, HEIGHT - 0.1, z - d / 2), (x + w / 2, HEIGHT - 0.05, z + d / 2))


def windows_along(a0, a1):
    n = max(1, int((a1 - a0) // 3.5))
    step = (a1 - a0) / n
    return [(a0 + step * (k + 0.5) - 0.7, a0 + step * (k + 0.5) + 0.7, 0.9, 2.2) for k in range(n)]


def draw_openings(rng, xs, bands, cols, door_bottom, windowless=None):
    """The doorways and windows, drawn in one fixed order for both modes: xopen[k] in the x-wall on band boundary k
    as (ua, ub, ya, yb), u along x; zopen[(b, c)] in the z-wall at xs[c] across band b, u along z (only walls that
    exist: interior z-walls of a corridor do not). Doors start at door_bottom (below the floor where they are cut
    through a slab); band `windowless` (a corridor) gets no window at its ends."""
    xopen = []
    for k in range(len(bands) + 1):
        below = bands[k - 1] if k > 0 else None
        above = bands[k] if k < len(bands) else None
        openings = []
        for c in range(cols):
            a0, a1 = xs[c] + 0.8, xs[c + 1] - 0.8
            if below is None or above is None:
                openings += windows_along(a0, a1)
            elif "corridor" in (below[2], above[2]):
                u = rng.uniform(a0, a1 - 1.2)
                openings.append((u, u + 1.2, door_bottom, 2.1))
            elif rng.random() < 0.5:  # back-to-back rooms: sometimes a connecting door
                u = rng.uniform(a0, a1 - 1.0)
                openings.append((u, u + 1.0, door_bottom, 2.1))
        xopen.append(openings)
    zopen = {}
    for b, (z0, z1, kind, _) in enumerate(bands):
        for c in range(cols + 1):
            outer = c in (0, cols)
            if not outer and kind == "corridor":
                continue
            openings = []
            if outer:
                if kind == "room":
                    openings = windows_along(z0 + 0.6, z1 - 0.6)
                elif b != windowless:
                    openings = [((z0 + z1) / 2 - 0.6, (z0 + z1) / 2 + 0.6, 0.9, 2.2)]
            elif rng.random() < 0.4:
                u = rng.uniform(z0 + 0.8, z1 - 1.8)
                openings.append((u, u + 1.0, door_bottom, 2.1))
            zopen[(b, c)] = openings
    return xopen, zopen


def emit(nodes, meshes, name, mb):
    """Adds mb as a mesh and a node named `name` (nothing when it is empty); returns its triangle count."""
    if mb.groups:
        meshes.append((name, mb))
        nodes.append({"name": name, "mesh": len(meshes) - 1})
    return mb.triangles


def layout(rng, target, uniform=False):
    """Column breakpoints xs (west to east) and bands (z0, z1, kind, row) south to north; the first draws of rng."""
    scale = max(target, 2000) / 10000.0
    # Area grows slower than detail, unless --uniform: then rooms in proportion to the target.
    n_rooms = max(4, round(6 * scale ** (1.0 if uniform else 0.87)))
    pairs = max(1, round(math.sqrt(n_rooms) / 3))  # room rows come in pairs around a corridor
    cols = math.ceil(n_rooms / (2 * pairs))
    widths = [round(rng.uniform(6.0, 8.0), 2) for _ in range(cols)]
    xs = [0.0]
    for w in widths:
        xs.append(xs[-1] + w)
    # Bands along z: room, corridor, room | room, corridor, room | ... (back-to-back rooms between pairs)
    bands = []  # (z0, z1, kind, row)
    z = 0.0
    row = 0
    for p in range(pairs):
        for kind in ("room", "corridor", "room"):
            depth = CORRIDOR_W if kind == "corridor" else round(rng.uniform(5.0, 7.0), 2)
            bands.append((z, z + depth, kind, row if kind == "room" else -1))
            if kind == "room":
                row += 1
            z += depth
    return xs, bands, cols


def generate(seed, target, uniform=False):
    rng = random.Random(seed)
    xs, bands, cols = layout(rng, target, uniform)
    xmin, xmax, zmin, zmax = xs[0], xs[-1], bands[0][0], bands[-1][1]
    rooms = [(b, c) for b in range(len(bands)) if bands[b][2] == "room" for c in range(cols)]

    nodes, meshes = [], []

    triangles = 0
    shell = MeshBuilder()
    ov = 0.1  # slabs reach 10 cm past the outer walls' faces, so their sides never line up with a wall face
    shell.box(MAT["floor"], (xmin - WALL_T / 2 - ov, -0.2, zmin - WALL_T / 2 - ov), (xmax + WALL_T / 2 + ov, 0.0, zmax + WALL_T / 2 + ov))
    shell.box(MAT["ceiling"], (xmin - WALL_T / 2 - ov, HEIGHT, zmin - WALL_T / 2 - ov), (xmax + WALL_T / 2 + ov, HEIGHT + 0.2, zmax + WALL_T / 2 + ov))

    # Doors run 1 m down into the floor slab (cut through it, as artists do).
    xopen, zopen = draw_openings(rng, xs, bands, cols, -1.0)
    # x-walls: one per band boundary, full length (their ends cover the corners).
    for k, openings in enumerate(xopen):
        zc = bands[0][0] if k == 0 else bands[k - 1][1]
        wall(shell, "x", zc, xmin - WALL_T / 2, xmax + WALL_T / 2, PEN_XWALL, openings)
    # z-walls: segments between adjacent x-walls, sunk 0.4 × thickness into them (not to their middle, so two
    # segments meeting one x-wall from both sides never share an end face).
    sink = 0.4 * WALL_T
    for (b, c), openings in zopen.items():
        z0, z1 = bands[b][0], bands[b][1]
        wall(shell, "z", xs[c], z0 + WALL_T / 2 - sink, z1 - WALL_T / 2 + sink, PEN_ZWALL, openings)
    # Corridor lights.
    for z0, z1, kind, _ in bands:
        if kind != "corridor":
            continue
        n = max(1, round((xmax - xmin) / 6))
        for k in range(n):
            panel(shell, xmin + (xmax - xmin) * (k + 0.5) / n, (z0 + z1) / 2, 1.0, 0.4)
    triangles += emit(nodes, meshes, "shell", shell)

    segments = 16 if uniform or target < 50000 else 32
    for idx, (b, c) in enumerate(rooms):
        z0, z1, _, row = bands[b]
        room = Room(xs[c] + WALL_T / 2, xs[c + 1] - WALL_T / 2, z0 + WALL_T / 2, z1 - WALL_T / 2)
        budget = (target - triangles) / (len(rooms) - idx)
        mb = MeshBuilder()
        cx, cz = (room.x0 + room.x1) / 2, (room.z0 + room.z1) / 2
        # Panels first (they hang from the ceiling, so they take no floor space).
        for px in (cx - (room.x1 - room.x0) / 4, cx + (room.x1 - room.x0) / 4):
            panel(mb, px, cz, 1.2, 0.6)
            room.ceiling.append((px - 0.6, cz - 0.3, px + 0.6, cz + 0.3))
        furnish(mb, rng, room, segments, (staircase, pillar, table, crates, shelf), lambda: mb.triangles < budget)
        triangles += emit(nodes, meshes, "room_%d_%d" % (row, c), mb)

    corridor = next(b for b in bands if b[2] == "corridor")
    return nodes, meshes, (xmin, xmax, zmin, zmax, (corridor[0] + corridor[1]) / 2), triangles


# ---------------------------------------------------------------------------------------------------------------
# --clean: parts meet without overlapping. Rooms and corridors are the inside surfaces of boxes (inward-facing),
# openings are short tunnels through the wall thickness, the building's outside is a box of outward faces, props
# stand on holes cut in the floor. Every face is a rectangle from rects_minus (or a pillar's triangles), so faces
# meet at edges and never share area.
SLAB = 0.2            # floor and roof slab thickness (the building's outside box reaches this far above/below)
PANEL_GAP = 0.01      # clean-mode light panels hang this far below the ceiling


def rects_minus(u0, u1, v0, v1, holes):
    """The rectangle [u0, u1] × [v0, v1] minus the rectangles `holes` (ua, ub, va, vb), as axis-aligned rectangles
    (u0, u1, v0, v1): the grid through every hole edge, free cells merged into runs across v, equal runs merged
    across u; the other orientation too, and the one with fewer rectangles wins. Breakpoints are the callers' own
    numbers, so a hole's edges coincide exactly with the faces of whatever fills it."""
    def decompose(u0, u1, v0, v1, holes):
        us = sorted({u0, u1, *[min(max(h[k], u0), u1) for h in holes for k in (0, 1)]})
        vs = sorted({v0, v1, *[min(max(h[k], v0), v1) for h in holes for k in (2, 3)]})

        def free(i, j):
            cu, cv = (us[i] + us[i + 1]) / 2, (vs[j] + vs[j + 1]) / 2
            return not any(h[0] < cu < h[1] and h[2] < cv < h[3] for h in holes)

        out, open_runs = [], []  # open_runs: [(ja, jb), first column]
        for i in range(len(us)):
            runs, j = [], 0
            while i < len(us) - 1 and j < len(vs) - 1:
                if free(i, j):
                    k = j
                    while k < len(vs) - 1 and free(i, k):
                        k += 1
                    runs.append((j, k))
                    j = k
                else:
                    j += 1
            still = []
            for run, start in open_runs:
                if run in runs:
                    still.append((run, start))
                else:
                    out.append((us[start], us[i], vs[run[0]], vs[run[1]]))
            started = [r for r, _ in still]
            open_runs = still + [(r, i) for r in runs if r not in started]
        return out

    a = decompose(u0, u1, v0, v1, holes)
    b = decompose(v0, v1, u0, u1, [(h[2], h[3], h[0], h[1]) for h in holes])
    return a if len(a) <= len(b) else [(r[2], r[3], r[0], r[1]) for r in b]


def _on_plane(axis, c, u, v):
    """A point of the plane {axis = c}: axis 0 (x): u along z, v along y; 1 (y): u along x, v along z; 2 (z): u
    along x, v along y."""
    if axis == 0:
        return (c, v, u)
    if axis == 1:
        return (u, c, v)
    return (u, v, c)


def plane_face(mb, mat, axis, c, sign, u0, u1, v0, v1, holes=()):
    """The rectangle [u0, u1] × [v0, v1] of the plane {axis = c} minus `holes`, facing along sign × the axis."""
    n = [0.0, 0.0, 0.0]
    n[axis] = float(sign)
    for a0, a1, b0, b1 in rects_minus(u0, u1, v0, v1, holes):
        mb.quad(mat, [_on_plane(axis, c, a0, b0), _on_plane(axis, c, a1, b0), _on_plane(axis, c, a1, b1),
                      _on_plane(axis, c, a0, b1)], tuple(n))


def clean_box(mb, mat, lo, hi, drop=(), holes=None):
    """An outward-facing box; faces named "-x", "+x", "-y", "+y", "-z", "+z". `drop`: faces left out (they rest on
    or against another face that has a hole for them); `holes`: face -> rectangles in that face's (u, v), see
    _on_plane (where another part touches it)."""
    holes = holes or {}
    for axis, name in enumerate("xyz"):
        ua, va = ((2, 1), (0, 2), (0, 1))[axis]
        for sign, c in ((-1, lo[axis]), (1, hi[axis])):
            key = ("-" if sign < 0 else "+") + name
            if key not in drop:
                plane_face(mb, mat, axis, c, sign, lo[ua], hi[ua], lo[va], hi[va], holes.get(key, ()))


def _tri(mb, mat, p, outward):
    n = _normalize(_cross(_sub(p[1], p[0]), _sub(p[2], p[0])))
    if _dot(n, outward) < 0:
        p, n = [p[0], p[2], p[1]], (-n[0], -n[1], -n[2])
    mb._poly(mat, p, n)


class CleanRoom(Room):
    """A room whose floor and ceiling are cut around what stands on / reaches them."""

    def __init__(self, x0, x1, z0, z1):
        super().__init__(x0, x1, z0, z1)
        self.floor_holes = []    # (x0, x1, z0, z1) footprints of props standing on the floor
        self.ceiling_holes = []  # footprints of pillars reaching the ceiling
        self.fillers = []        # pillars: (ring, corners), the floor/ceiling between a round pillar and its square hole


def table_clean(mb, rng, room):
    r = place_table(rng, room)
    if not r:
        return False
    h = TABLE_H
    under = h - 0.05
    legs = table_legs(r)
    clean_box(mb, MAT["wood"], (r[0], under, r[1]), (r[2], h, r[3]), holes={"-y": legs})
    for x0, x1, z0, z1 in legs:  # legs run from the floor to the underside of the top, both cut for them
        clean_box(mb, MAT["wood"], (x0, 0.0, z0), (x1, under, z1), drop=("-y", "+y"))
        room.floor_holes.append((x0, x1, z0, z1))
    return True


def crates_clean(mb, rng, room):
    placed = place_crate(rng, room)
    if not placed:
        return False
    s, r, top = placed  # top: a smaller crate standing on it
    clean_box(mb, MAT["crate"], (r[0], 0.0, r[1]), (r[2], s, r[3]), drop=("-y",), holes={"+y": [top]} if top else None)
    if top:
        clean_box(mb, MAT["crate"], (top[0], s, top[2]), (top[1], s + s * TOP_CRATE, top[3]), drop=("-y",))
    room.floor_holes.append((r[0], r[2], r[1], r[3]))
    return True


def shelf_clean(mb, rng, room):
    r = place_shelf(rng, room)
    if not r:
        return False
    h = SHELF_H
    in0, in1 = r[0] + 0.04, r[2] - 0.04  # inner faces of the two uprights; the boards span exactly between them
    zb0, zb1 = r[1] + 0.01, r[3] - 0.01
    boards, ends = 4, []
    for b in range(boards):
        y = 0.1 + b * (h - 0.2) / (boards - 1)
        yb = y - 0.025
        books = []
        x = r[0] + 0.06
        while b != boards - 1:
            bw = rng.uniform(0.03, 0.07)
            if x + bw > r[2] - 0.06:
                break
            bh = rng.uniform(0.18, 0.32)
            bd = round(rng.uniform(0.22, 0.3), 2)  # whole cm: the board's top, cut around the books, gets no slivers
            mat = MAT[rng.choice(("book_red", "book_blue", "book_green"))]
            books.append((x, x + bw, r[1] + 0.04, r[1] + 0.04 + bd, bh, mat))
            x += bw + rng.uniform(0.005, 0.02)
        clean_box(mb, MAT["wood"], (in0, yb, zb0), (in1, y, zb1), drop=("-x", "+x"), holes={"+y": [k[:4] for k in books]})
        for bx0, bx1, bz0, bz1, bh, mat in books:  # books stand on the board, which is cut for them
            clean_box(mb, mat, (bx0, y, bz0), (bx1, y + bh, bz1), drop=("-y",))
        ends.append((zb0, zb1, yb, y))
    clean_box(mb, MAT["wood"], (r[0], 0.0, r[1]), (in0, h, r[3]), drop=("-y",), holes={"+x": ends})
    clean_box(mb, MAT["wood"], (in1, 0.0, r[1]), (r[2], h, r[3]), drop=("-y",), holes={"-x": ends})
    room.floor_holes += [(r[0], in0, r[1], r[3]), (in1, r[2], r[1], r[3])]
    return True


def pillar_clean(mb, rng, room, segments):
    """A round pillar from floor to ceiling. Its footprint square is a hole in both; the part of the square around
    the pillar is filled by triangles fanning from the square's corners (the 4 ring vertices on the square's sides
    are set to the square's own coordinates, so the fans meet the hole's edges exactly)."""
    placed = place_pillar(rng, room)
    if not placed:
        return False
    rad, r = placed
    cx, cz = (r[0] + r[2]) / 2, (r[1] + r[3]) / 2
    ring = [(cx + rad * math.cos(2 * math.pi * k / segments), cz + rad * math.sin(2 * math.pi * k / segments))
            for k in range(segments)]
    q = segments // 4
    ring[0], ring[q], ring[2 * q], ring[3 * q] = (r[2], cz), (cx, r[3]), (r[0], cz), (cx, r[1])
    for k in range(segments):
        a, b = ring[k], ring[(k + 1) % segments]
        mid = ((a[0] + b[0]) / 2 - cx, 0.0, (a[1] + b[1]) / 2 - cz)
        mb.quad(MAT["concrete"], [(a[0], 0.0, a[1]), (b[0], 0.0, b[1]), (b[0], HEIGHT, b[1]), (a[0], HEIGHT, a[1])], mid)
    room.floor_holes.append((r[0], r[2], r[1], r[3]))
    room.ceiling_holes.append((r[0], r[2], r[1], r[3]))
    room.fillers.append((ring, ((r[2], r[3]), (r[0], r[3]), (r[0], r[1]), (r[2], r[1]))))
    return True


def staircase_clean(mb, rng, room):
    placed = place_staircase(rng, room)
    if not placed:
        return False
    steps, rise, run, width, platform, r = placed
    u0, w0 = r[0], r[1]
    w1 = w0 + width
    us = [u0 + k * run for k in range(steps + 1)] + [u0 + steps * run + platform]
    ys = [0.0] + [(k + 1) * rise for k in range(steps)]
    grid_solid(mb, MAT["concrete"], us, ys, lambda i, j: j <= min(i, steps - 1), "x", w0, w1, bottom=False)
    room.floor_holes.append((us[0], us[-1], w0, w1))
    return True


def cavity(mb, x0, x1, z0, z1, holes_zlo, holes_zhi, holes_xlo, holes_xhi, floor_holes=(), ceiling_holes=(), fillers=()):
    """The inside of a room or corridor: floor, ceiling and four walls facing inwards, the walls cut where the
    openings are (holes_zlo: openings in the wall at z = z0, in (x, y); holes_xlo: in the wall at x = x0, (z, y))."""
    plane_face(mb, MAT["wall"], 2, z0, 1, x0, x1, 0.0, HEIGHT, holes_zlo)
    plane_face(mb, MAT["wall"], 2, z1, -1, x0, x1, 0.0, HEIGHT, holes_zhi)
    plane_face(mb, MAT["wall"], 0, x0, 1, z0, z1, 0.0, HEIGHT, holes_xlo)
    plane_face(mb, MAT["wall"], 0, x1, -1, z0, z1, 0.0, HEIGHT, holes_xhi)
    plane_face(mb, MAT["floor"], 1, 0.0, 1, x0, x1, z0, z1, floor_holes)
    plane_face(mb, MAT["ceiling"], 1, HEIGHT, -1, x0, x1, z0, z1, ceiling_holes)
    for ring, corners in fillers:
        q = len(ring) // 4
        for k in range(len(ring)):
            a, b, c = ring[k], ring[(k + 1) % len(ring)], corners[k // q]
            _tri(mb, MAT["floor"], [(a[0], 0.0, a[1]), (b[0], 0.0, b[1]), (c[0], 0.0, c[1])], (0.0, 1.0, 0.0))
            _tri(mb, MAT["ceiling"], [(a[0], HEIGHT, a[1]), (b[0], HEIGHT, b[1]), (c[0], HEIGHT, c[1])], (0.0, -1.0, 0.0))


def tunnel(mb, axis, centre, o):
    """The reveals of opening o = (ua, ub, ya, yb) through a wall of thickness WALL_T centred on `centre` (z for an
    x-wall, x for a z-wall): two jambs, the head, and the sill (a door's threshold is floor)."""
    ua, ub, ya, yb = o
    w0, w1 = centre - WALL_T / 2, centre + WALL_T / 2
    sill = MAT["floor"] if ya == 0.0 else MAT["wall"]
    if axis == "x":
        plane_face(mb, MAT["wall"], 0, ua, 1, w0, w1, ya, yb)
        plane_face(mb, MAT["wall"], 0, ub, -1, w0, w1, ya, yb)
        plane_face(mb, MAT["wall"], 1, yb, -1, ua, ub, w0, w1)
        plane_face(mb, sill, 1, ya, 1, ua, ub, w0, w1)
    else:
        plane_face(mb, MAT["wall"], 2, ua, 1, w0, w1, ya, yb)
        plane_face(mb, MAT["wall"], 2, ub, -1, w0, w1, ya, yb)
        plane_face(mb, MAT["wall"], 1, yb, -1, w0, w1, ua, ub)
        plane_face(mb, sill, 1, ya, 1, w0, w1, ua, ub)


def generate_clean(seed, target, uniform=False):
    """The --clean level: same layout and doorways as generate() for the same seed and size, built so that parts
    meet without overlapping (see the module docstring)."""
    rng = random.Random(seed)
    xs, bands, cols = layout(rng, target, uniform)
    xmin, xmax, zmin, zmax = xs[0], xs[-1], bands[0][0], bands[-1][1]
    rooms = [(b, c) for b in range(len(bands)) if bands[b][2] == "room" for c in range(cols)]
    corridors = [b for b in range(len(bands)) if bands[b][2] == "corridor"]
    h = WALL_T / 2

    # Openings in generate()'s order; doors stand on the floor; the first corridor has no window.
    xopen, zopen = draw_openings(rng, xs, bands, cols, 0.0, windowless=corridors[0])
    n_lit = max(1, len(rooms) // 2)
    lit = set(rng.sample(range(len(rooms)), n_lit))  # rooms with ceiling panels; the others are lit by daylight only

    def within(openings, a, b):
        return [o for o in openings if a < o[0] and o[1] < b]

    nodes, meshes = [], []

    # The outside of the building (outward faces, windows cut), and every opening's tunnel.
    shell = MeshBuilder()
    X0, X1, Z0, Z1, Y0, Y1 = xmin - h, xmax + h, zmin - h, zmax + h, -SLAB, HEIGHT + SLAB
    plane_face(shell, MAT["wall"], 2, Z0, -1, X0, X1, Y0, Y1, xopen[0])
    plane_face(shell, MAT["wall"], 2, Z1, 1, X0, X1, Y0, Y1, xopen[-1])
    plane_face(shell, MAT["wall"], 0, X0, -1, Z0, Z1, Y0, Y1, [o for b in range(len(bands)) for o in zopen[(b, 0)]])
    plane_face(shell, MAT["wall"], 0, X1, 1, Z0, Z1, Y0, Y1, [o for b in range(len(bands)) for o in zopen[(b, cols)]])
    plane_face(shell, MAT["ceiling"], 1, Y1, 1, X0, X1, Z0, Z1)
    plane_face(shell, MAT["floor"], 1, Y0, -1, X0, X1, Z0, Z1)
    windows = doors = 0
    for k, openings in enumerate(xopen):
        zc = bands[0][0] if k == 0 else bands[k - 1][1]
        for o in openings:
            tunnel(shell, "x", zc, o)
    for b in range(len(bands)):
        for c in range(cols + 1):
            for o in zopen.get((b, c), ()):
                tunnel(shell, "z", xs[c], o)
    for o in [o for ops in xopen for o in ops] + [o for ops in zopen.values() for o in ops]:
        windows, doors = windows + (o[2] > 0.0), doors + (o[2] == 0.0)
    triangles = emit(nodes, meshes, "shell", shell)

    panels = 0
    for k, b in enumerate(corridors):
        z0, z1 = bands[b][0], bands[b][1]
        mb = MeshBuilder()
        cavity(mb, xmin + h, xmax - h, z0 + h, z1 - h, xopen[b], xopen[b + 1], zopen[(b, 0)], zopen[(b, cols)])
        if k > 0:  # the first corridor is lit only through its doorways
            n = max(1, round((xmax - xmin) / 6))
            for i in range(n):
                px, pz = xmin + (xmax - xmin) * (i + 0.5) / n, (z0 + z1) / 2
                plane_face(mb, MAT["panel"], 1, HEIGHT - PANEL_GAP, -1, px - 0.5, px + 0.5, pz - 0.2, pz + 0.2)
                panels += 1
        triangles += emit(nodes, meshes, "corridor_%d" % k, mb)

    segments = 16 if uniform or target < 50000 else 32
    for idx, (b, c) in enumerate(rooms):
        z0, z1, _, row = bands[b]
        room = CleanRoom(xs[c] + h, xs[c + 1] - h, z0 + h, z1 - h)
        budget = (target - triangles) / (len(rooms) - idx)
        mb, walls = MeshBuilder(), MeshBuilder()
        # Walls first, only to count them against the budget; the room's cavity is emitted after its props.
        cavity(walls, room.x0, room.x1, room.z0, room.z1, within(xopen[b], room.x0, room.x1),
               within(xopen[b + 1], room.x0, room.x1), zopen[(b, c)], zopen[(b, c + 1)])
        cx, cz = (room.x0 + room.x1) / 2, (room.z0 + room.z1) / 2
        if idx in lit:
            for px in (cx - (room.x1 - room.x0) / 4, cx + (room.x1 - room.x0) / 4):
                plane_face(mb, MAT["panel"], 1, HEIGHT - PANEL_GAP, -1, px - 0.6, px + 0.6, cz - 0.3, cz + 0.3)
                room.ceiling.append((px - 0.6, cz - 0.3, px + 0.6, cz + 0.3))
                panels += 1
        furnish(mb, rng, room, segments, (staircase_clean, pillar_clean, table_clean, crates_clean, shelf_clean),
                lambda: mb.triangles + walls.triangles + 4 * len(room.floor_holes) < budget)
        cavity(mb, room.x0, room.x1, room.z0, room.z1, within(xopen[b], room.x0, room.x1),
               within(xopen[b + 1], room.x0, room.x1), zopen[(b, c)], zopen[(b, c + 1)],
               room.floor_holes, room.ceiling_holes, room.fillers)
        triangles += emit(nodes, meshes, "room_%d_%d" % (row, c), mb)

    corridor = bands[corridors[0]]
    stats = {"rooms": len(rooms), "corridors": len(corridors), "windows": windows, "doorways": doors,
             "panels": panels, "rooms_with_panels": len(lit)}
    return nodes, meshes, (xmin, xmax, zmin, zmax, (corridor[0] + corridor[1]) / 2), triangles, stats


def quat_from_to(a, b):
    a, b = _normalize(a), _normalize(b)
    c = _cross(a, b)
    w = 1.0 + _dot(a, b)
    q = (c[0], c[1], c[2], w)
    n = math.sqrt(sum(v * v for v in q))
    return [q[0] / n, q[1] / n, q[2] / n, q[3] / n]


def write_gltf(path, nodes, meshes, extent, seed, clean=False, tiles=1, tile_gap=TILE_GAP):
    binary = bytearray()
    buffer_views, accessors, gltf_meshes = [], [], []

    def add_view(data, target):
        while len(binary) % 4:
            binary.append(0)
        buffer_views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data), "target": target})
        binary.extend(data)
        return len(buffer_views) - 1

    for name, mb in meshes:
        prims = []
        for mat, (pos, nor, idx) in mb.groups.items():
            pdata = b"".join(struct.pack("<3f", *p) for p in pos)
            ndata = b"".join(struct.pack("<3f", *n) for n in nor)
            big = len(pos) > 65535
            idata = struct.pack("<%d%s" % (len(idx), "I" if big else "H"), *idx)
            pv, nv, iv = add_view(pdata, 34962), add_view(ndata, 34962), add_view(idata, 34963)
            # min/max from the float32 values actually stored, as the validator checks.
            stored = [struct.unpack("<3f", struct.pack("<3f", *p)) for p in pos]
            lo = [min(p[k] for p in stored) for k in range(3)]
            hi = [max(p[k] for p in stored) for k in range(3)]
            accessors.append({"bufferView": pv, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": lo, "max": hi})
            accessors.append({"bufferView": nv, "componentType": 5126, "count": len(nor), "type": "VEC3"})
            accessors.append({"bufferView": iv, "componentType": 5125 if big else 5123, "count": len(idx), "type": "SCALAR"})
            a = len(accessors)
            prims.append({"attributes": {"POSITION": a - 3, "NORMAL": a - 2}, "indices": a - 1, "material": mat})
        gltf_meshes.append({"name": name, "primitives": prims})

    materials = []
    for name, base, emissive, strength in MATERIALS:
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": [*base, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.9}}
        if emissive:
            m["emissiveFactor"] = list(emissive)
            m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
        materials.append(m)

    xmin, xmax, zmin, zmax, corridor_z = extent
    sun_dir = (0.35, -0.8, 0.48)
    if tiles > 1:
        # Copies of the level's nodes under one node per tile (rows of ceil(sqrt(tiles)), tile_gap apart), sharing
        # their meshes: more level with exactly the same content per square metre.
        per_row = math.ceil(math.sqrt(tiles))
        all_nodes, roots = [], []
        for t in range(tiles):
            first = len(all_nodes)
            all_nodes += [dict(n, name="%s_t%d" % (n["name"], t)) for n in nodes]
            all_nodes.append({"name": "tile_%d" % t, "children": list(range(first, first + len(nodes))),
                              "translation": [(t % per_row) * (xmax - xmin + tile_gap), 0.0,
                                              (t // per_row) * (zmax - zmin + tile_gap)]})
            roots.append(len(all_nodes) - 1)
    else:
        all_nodes = list(nodes)
        roots = list(range(len(all_nodes)))
    all_nodes.append({"name": "sun", "rotation": quat_from_to((0, 0, -1), sun_dir),
                      "extensions": {"KHR_lights_punctual": {"light": 0}}})
    # The camera stands at the west end of the first corridor, looking east (-Z of the camera node = +X).
    all_nodes.append({"name": "camera", "camera": 0, "translation": [xmin + 1.0, 1.7, corridor_z],
                      "rotation": quat_from_to((0, 0, -1), (1, 0, 0))})
    scene_nodes = roots + [len(all_nodes) - 2, len(all_nodes) - 1]
    bin_name = os.path.splitext(os.path.basename(path))[0] + ".bin"
    doc = {
        "asset": {"version": "2.0", "generator": "hemibake examples/generate_level.py (seed %d%s%s)" % (
            seed, ", clean" if clean else "", ", %d tiles" % tiles if tiles > 1 else "")},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"name": "sun", "type": "directional", "color": [1.0, 0.96, 0.9], "intensity": 40.0}]}},
        "scene": 0,
        "scenes": [{"name": "level", "nodes": scene_nodes}],
        "nodes": all_nodes,
        "meshes": gltf_meshes,
        "materials": materials,
        "cameras": [{"name": "camera", "type": "perspective", "perspective": {"yfov": 1.1, "znear": 0.05, "zfar": 500.0, "aspectRatio": 1.7778}}],
        "accessors": accessors,
        "bufferViews": buffer_views,
        "buffers": [{"uri": bin_name, "byteLength": len(binary)}],
    }
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    with open(os.path.join(os.path.dirname(path) or ".", bin_name), "wb") as f:
        f.write(binary)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=next(p for p in __doc__.split("\n\n") if p.startswith("--clean")),
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seed", type=int, default=1, help="random seed (same seed + size = same file)")
    ap.add_argument("--triangles", type=int, default=10000, help="approximate triangle count (size of the level)")
    ap.add_argument("-o", "--output", required=True, help="output .gltf (a .bin of the same name is written beside it)")
    ap.add_argument("--uniform", action="store_true",
                    help="the same detail per square metre at every size: rooms in proportion to --triangles and "
                         "16-sided pillars (by default bigger levels get more rooms and more detail per room, and "
                         "32-sided pillars from 50k triangles)")
    ap.add_argument("--clean", action="store_true",
                    help="parts meet without overlapping (no face under or through a solid, none sharing area); "
                         "for judging a baker's convergence apart from leaks (see below)")
    ap.add_argument("--tiles", type=int, default=1,
                    help="that many copies of the level side by side, 10 m apart (rows of ceil(sqrt(N))), sharing "
                         "their meshes: a bigger level with exactly the same content per square metre, to measure "
                         "how a baker's cost grows with the level's size alone")
    ap.add_argument("--tile-gap", type=float, default=TILE_GAP,
                    help="metres between copies (--tiles), 10 by default; copies a kilometre apart do not light or "
                         "shade each other, and each is an island of its own with its own ray epsilon and offsets "
                         "(README, parts kilometres apart; give hemibake --patch-size and --element-size, the "
                         "presets size patches from the whole diagonal)")
    args = ap.parse_args()
    if args.tiles < 1:
        ap.error("--tiles must be at least 1")
    if not (args.tile_gap >= 0.0 and math.isfinite(args.tile_gap)):
        ap.error("--tile-gap must be a finite number of metres, at least 0")
    if not args.clean:
        nodes, meshes, extent, triangles = generate(args.seed, args.triangles, args.uniform)
        write_gltf(args.output, nodes, meshes, extent, args.seed, tiles=args.tiles, tile_gap=args.tile_gap)
        print("%s: %d triangles, %d nodes, %.1f x %.1f m%s" % (args.output, triangles * args.tiles, len(nodes), extent[1] - extent[0],
                                                        extent[3] - extent[2], " a tile, %d tiles" % args.tiles if args.tiles > 1 else ""))
        return
    nodes, meshes, extent, triangles, stats = generate_clean(args.seed, args.triangles, args.uniform)
    write_gltf(args.output, nodes, meshes, extent, args.seed, clean=True, tiles=args.tiles, tile_gap=args.tile_gap)
    pts = [p for _, mb in meshes for pos, _, _ in mb.groups.values() for p in pos]
    lo, hi = [min(p[k] for p in pts) for k in range(3)], [max(p[k] for p in pts) for k in range(3)]
    print("%s: %d triangles, %d nodes, bounds (%.2f %.2f %.2f)-(%.2f %.2f %.2f) m%s" % (
        args.output, triangles * args.tiles, len(nodes), *lo, *hi, " a tile, %d tiles" % args.tiles if args.tiles > 1 else ""))
    print("  %d rooms (%d with panels), %d corridors, %d windows, %d doorways, %d panels" % (
        stats["rooms"], stats["rooms_with_panels"], stats["corridors"], stats["windows"], stats["doorways"], stats["panels"]))


if __name__ == "__main__":
    main()
