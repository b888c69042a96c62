#!/usr/bin/env python3
"""Writes the sample query meshes in data/samples/ (closed, outward-wound, metres). Deterministic: the
committed files are this script's output. Usage: scripts/make_samples.py [DIR]"""
import math
import os
import sys


def uv_surface(radius_at, slices, stacks):
    """A closed surface of revolution-like mesh: point(theta, phi) for theta around z, phi from the south
    pole (0) to the north pole (pi); poles are single vertices."""
    verts = [radius_at(0.0, 0.0)]
    for j in range(1, stacks):
        phi = math.pi * j / stacks
        for i in range(slices):
            verts.append(radius_at(2 * math.pi * i / slices, phi))
    verts.append(radius_at(0.0, math.pi))
    north = len(verts) - 1
    ring = lambda j, i: 1 + (j - 1) * slices + (i % slices)
    faces = []
    for i in range(slices):
        faces.append((0, ring(1, i + 1), ring(1, i)))
        faces.append((north, ring(stacks - 1, i), ring(stacks - 1, i + 1)))
    for j in range(1, stacks - 1):
        for i in range(slices):
            a, b, c, d = ring(j, i), ring(j, i + 1), ring(j + 1, i + 1), ring(j + 1, i)
            faces += [(a, b, c), (a, c, d)]
    return verts, faces


def superellipsoid(rx, ry, rz, e):
    def point(theta, phi):
        sp, cp = math.sin(phi), -math.cos(phi)
        f = lambda x, p: math.copysign(abs(x) ** p, x)
        return (rx * f(sp, e) * f(math.cos(theta), e), ry * f(sp, e) * f(math.sin(theta), e), rz * f(cp, e))
    return uv_surface(point, 48, 24)


def egg(r, length):
    def point(theta, phi):
        z = -math.cos(phi)
        s = math.sin(phi) * (1.0 + 0.18 * z)  # fatter at the top
        return (r * s * math.cos(theta), r * s * math.sin(theta), 0.5 * length * z)
    return uv_surface(point, 40, 30)


def prism(polygon, length):
    """A right prism along z over a convex polygon given counter-clockwise; caps fanned about centres."""
    n = len(polygon)
    verts = [(x, y, -length / 2) for x, y in polygon] + [(x, y, length / 2) for x, y in polygon]
    cx = sum(p[0] for p in polygon) / n
    cy = sum(p[1] for p in polygon) / n
    verts += [(cx, cy, -length / 2), (cx, cy, length / 2)]
    bottom, top = 2 * n, 2 * n + 1
    faces = []
    for i in range(n):
        j = (i + 1) % n
        faces += [(i, j, n + j), (i, n + j, n + i), (bottom, j, i), (top, n + i, n + j)]
    return verts, faces


def wedge(length, width, low, high):
    """A doorstop: a box whose top slopes from `low` to `high` along x."""
    x0, x1, y0, y1 = -length / 2, length / 2, -width / 2, width / 2
    v = [(x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0), (x0, y0, low), (x1, y0, high), (x1, y1, high),
         (x0, y1, low)]
    f = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4), (1, 2, 6), (1, 6, 5), (2, 3, 7),
         (2, 7, 6), (3, 0, 4), (3, 4, 7)]
    return v, f


def rotate(verts, axis, angle, offset):
    ax = [c / math.sqrt(sum(a * a for a in axis)) for c in axis]
    c, s = math.cos(angle), math.sin(angle)
    out = []
    for p in verts:
        d = sum(a * b for a, b in zip(ax, p))
        cr = (ax[1] * p[2] - ax[2] * p[1], ax[2] * p[0] - ax[0] * p[2], ax[0] * p[1] - ax[1] * p[0])
        q = [p[k] * c + cr[k] * s + ax[k] * d * (1 - c) + offset[k] for k in range(3)]
        out.append(tuple(q))
    return out


def write_obj(path, verts, faces, comment):
    with open(path, "w") as f:
        f.write(f"# {comment}\n# {len(verts)} vertices, {len(faces)} faces, metres\n")
        for v in verts:
            f.write("v %.9g %.9g %.9g\n" % v)
        for t in faces:
            f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "data", "samples")
    os.makedirs(out, exist_ok=True)
    hexagon = [(0.006 * math.cos(k * math.pi / 3), 0.006 * math.sin(k * math.pi / 3)) for k in range(6)]
    samples = {
        "soap": (superellipsoid(0.045, 0.03, 0.015, 0.4), "bar of soap: superellipsoid 9 x 6 x 3 cm"),
        "egg": (egg(0.021, 0.058), "egg: 4.2 cm wide, 5.8 cm long, fatter at one end"),
        "hex-rod": (prism(hexagon, 0.15), "hexagonal rod: 1.2 cm across the corners, 15 cm long"),
        "doorstop": (wedge(0.14, 0.05, 0.005, 0.035), "doorstop: 14 x 5 cm, sloping from 0.5 to 3.5 cm"),
    }
    for name, ((verts, faces), comment) in samples.items():
        # Each in a frame of its own: turned and moved, as a real asset would be.
        k = len(name)
        verts = rotate(verts, (1.0, 0.3 * k, -0.5), 0.37 * k, (0.1 * k, -0.05 * k, 0.02 * k))
        write_obj(os.path.join(out, name + ".obj"), verts, faces, comment)


if __name__ == "__main__":
    main()
