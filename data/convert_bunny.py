#!/usr/bin/env python3
"""Converts the Stanford bunny of the npm package `bunny` (index.js: exports.positions, exports.cells)
into data/bunny.ply: watertight, about 0.5 units tall, standing on y = 0 with +y up, and with per-vertex
colours after Figure 8 of "Rendering diffuse objects using particle systems inside voxelized surface
geometry" (Juckel & Beckhaus): light brown-grey fur, red at the nose, eyes and ears, white at the tail.

The original scan has holes in its base (the mesh of bunny 1.0.1 is already closed: the script finds no
hole there, but checks). Each boundary loop is closed by a fan from the loop's centroid, wound so the new
triangles agree with the orientation of the triangles around the hole.

Usage: python3 convert_bunny.py path/to/package/index.js path/to/bunny.ply
"""
import json
import sys
from collections import defaultdict


def load(path):
    text = open(path).read()
    p0 = text.index("exports.positions=") + len("exports.positions=")
    c0 = text.index("exports.cells=")
    positions = json.loads(text[p0:c0].strip().rstrip(";"))
    cells = json.loads(text[c0 + len("exports.cells="):].strip().rstrip(";"))
    return positions, cells


def boundary_loops(cells):
    # A directed edge whose reverse no triangle uses lies on a hole; walking those edges head to tail
    # traces each hole's boundary in the orientation of the surface around it.
    directed = set()
    for a, b, c in cells:
        directed.update(((a, b), (b, c), (c, a)))
    nxt = {}
    for a, b in directed:
        if (b, a) not in directed:
            if a in nxt:
                raise SystemExit("boundary vertex %d is on two holes; fill by hand" % a)
            nxt[a] = b
    loops, seen = [], set()
    for start in sorted(nxt):
        if start in seen:
            continue
        loop, v = [], start
        while v not in seen:
            seen.add(v)
            loop.append(v)
            v = nxt[v]
        if v != start:
            raise SystemExit("open boundary chain at vertex %d" % start)
        loops.append(loop)
    return loops


def close_holes(positions, cells):
    loops = boundary_loops(cells)
    print("%d holes to close" % len(loops))
    for loop in loops:
        centroid = [sum(positions[v][k] for v in loop) / len(loop) for k in range(3)]
        centre = len(positions)
        positions.append(centroid)
        # Boundary edge a -> b belongs to a surface triangle; the fan triangle uses it as b -> a.
        for i, a in enumerate(loop):
            b = loop[(i + 1) % len(loop)]
            cells.append([b, a, centre])


def check_closed(cells):
    count = defaultdict(int)
    for a, b, c in cells:
        for e in ((a, b), (b, c), (c, a)):
            count[(min(e), max(e))] += 1
    bad = [e for e, n in count.items() if n != 2]
    if bad:
        raise SystemExit("still %d edges not shared by exactly two triangles" % len(bad))


def colour(p, lo, hi):
    # Regions by position in the unit box of the bounds (y up; the bunny faces -x, its tail at +x).
    # Rough boxes are enough: a diffuse object blurs them anyway.
    x, y, z = ((p[k] - lo[k]) / (hi[k] - lo[k]) for k in range(3))
    fur = (0.72, 0.62, 0.52)
    red = (0.80, 0.22, 0.18)
    white = (0.97, 0.97, 0.95)
    if y > 0.78:  # the ears rise above the head
        return red
    if x < 0.07 and 0.45 < y < 0.78:  # the nose at the front of the head
        return red
    if x < 0.2 and 0.62 < y < 0.78 and (z < 0.35 or z > 0.65):  # the eyes on either side
        return red
    if x > 0.9 and 0.1 < y < 0.5:  # the tail at the rear
        return white
    return fur


def main():
    src, dst = sys.argv[1], sys.argv[2]
    positions, cells = load(src)
    close_holes(positions, cells)
    check_closed(cells)
    lo = [min(p[k] for p in positions) for k in range(3)]
    hi = [max(p[k] for p in positions) for k in range(3)]
    scale = 0.5 / (hi[1] - lo[1])
    cx, cz = (lo[0] + hi[0]) / 2, (lo[2] + hi[2]) / 2
    out = [[(p[0] - cx) * scale, (p[1] - lo[1]) * scale, (p[2] - cz) * scale] for p in positions]
    nlo = [min(p[k] for p in out) for k in range(3)]
    nhi = [max(p[k] for p in out) for k in range(3)]
    with open(dst, "w") as f:
        f.write("ply\nformat ascii 1.0\n")
        f.write("comment Stanford bunny (Stanford 3D Scanning Repository), holes closed; see README.md\n")
        f.write("element vertex %d\n" % len(out))
        f.write("property float x\nproperty float y\nproperty float z\n")
        f.write("property uchar red\nproperty uchar green\nproperty uchar blue\n")
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(cells))
        for p in out:
            r, g, b = colour(p, nlo, nhi)
            f.write("%.6f %.6f %.6f %d %d %d\n" % (p[0], p[1], p[2], round(r * 255), round(g * 255),
                                                   round(b * 255)))
        for a, b, c in cells:
            f.write("3 %d %d %d\n" % (a, b, c))
    print("%d vertices, %d triangles, bounds %s .. %s" % (len(out), len(cells), nlo, nhi))


if __name__ == "__main__":
    main()
