#!/usr/bin/env python3
"""Writes scenes/instances/knot.ply (a (2,3) torus knot tube, 12 288 triangles, binary
PLY with normals) and scenes/instances.toml (a field of 400 of them: one mesh stored once,
placed 400 times). Deterministic; run from anywhere: python3 scenes/instances/make.py"""

import math
import os
import random
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
P, Q = 2, 3
ALONG, AROUND = 512, 12  # segments along the knot and around the tube
TUBE = 0.11


def knot(t):
    r = 0.5 + 0.25 * math.cos(Q * t)
    return (r * math.cos(P * t), 0.25 * math.sin(Q * t), r * math.sin(P * t))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def unit(a):
    n = math.sqrt(sum(x * x for x in a))
    return tuple(x / n for x in a)


def write_ply(path):
    verts, faces = [], []
    for i in range(ALONG):
        t = 2 * math.pi * i / ALONG
        c = knot(t)
        tangent = unit(sub(knot(t + 1e-3), knot(t - 1e-3)))
        side = unit(cross(tangent, (0.0, 1.0, 0.0)))
        up = cross(side, tangent)
        for j in range(AROUND):
            a = 2 * math.pi * j / AROUND
            n = tuple(math.cos(a) * s + math.sin(a) * u for s, u in zip(side, up))
            verts.append(tuple(ci + TUBE * ni for ci, ni in zip(c, n)) + n)
    for i in range(ALONG):
        for j in range(AROUND):
            a = i * AROUND + j
            b = ((i + 1) % ALONG) * AROUND + j
            a1 = i * AROUND + (j + 1) % AROUND
            b1 = ((i + 1) % ALONG) * AROUND + (j + 1) % AROUND
            faces += [(a, b, b1), (a, b1, a1)]
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment (2,3) torus knot tube, written by scenes/instances/make.py\n"
        f"element vertex {len(verts)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        for v in verts:
            f.write(struct.pack("<6f", *v))
        for tri in faces:
            f.write(struct.pack("<B3i", 3, *tri))
    return len(faces)


def write_scene(path, triangles):
    rng = random.Random(10)
    n = 20
    entries = {"gold": [], "red": [], "white": []}
    for i in range(n):
        for j in range(n):
            x = (i - (n - 1) / 2) * 2.3 + rng.uniform(-0.4, 0.4)
            z = (j - (n - 1) / 2) * 2.3 + rng.uniform(-0.4, 0.4)
            s = rng.uniform(0.8, 1.25)
            steps = [
                f"{{ rotate = {{ axis = [0, 1, 0], angle = {rng.uniform(0, 360):.1f} }} }}",
                f"{{ rotate = {{ axis = [1, 0, 0], angle = {rng.uniform(-25, 25):.1f} }} }}",
                f"{{ scale = {s:.3f} }}",
                f"{{ translate = [{x:.3f}, {0.36 * s:.3f}, {z:.3f}] }}",
            ]
            entries[rng.choice(list(entries))].append("  [" + ", ".join(steps) + "],")
    total = sum(len(v) for v in entries.values())
    out = [
        f"# {total} torus knots of one {triangles}-triangle mesh (scenes/instances/knot.ply):",
        f"# stored once, rendered {total * triangles} triangles. Written by",
        "# scenes/instances/make.py. `candela info` shows the stored and rendered counts.",
        "#",
        "#   cargo run --release -- render scenes/instances.toml -o instances.png",
        "",
        "[render]",
        "resolution = [480, 270]",
        "spp = 128",
        "max_depth = 5",
        "",
        "[camera]",
        "position = [0, 8, 21]",
        "look_at = [0, 0, 0]",
        "fov = 42",
        "",
        "[materials.gold]",
        'type = "conductor"',
        'preset = "Au"',
        "alpha = 0.15",
        "",
        "[materials.red]",
        'type = "plastic"',
        "albedo = [0.6, 0.06, 0.04]",
        "",
        "[materials.white]",
        'type = "diffuse"',
        "albedo = 0.75",
        "",
        "[materials.floor]",
        'type = "diffuse"',
        'albedo = { type = "checker", a = 0.5, b = 0.25, uv_scale = [20, 20] }',
        "",
        "[[shape]]",
        'type = "rectangle"',
        'material = "floor"',
        "transform = [{ scale = 40 }, { rotate = { axis = [1, 0, 0], angle = -90 } }]",
        "",
        "[[shape]]",
        'type = "rectangle"',
        'material = "white"',
        "emission = 4",
        "transform = [{ scale = [8, 5, 1] }, { look_at = { origin = [-8, 14, 10], target = [0, 0, 0] } }]",
        "",
        "[environment]",
        "constant = [0.12, 0.16, 0.24]",
    ]
    for material, steps in entries.items():
        out += [
            "",
            "[[shape]]",
            'type = "mesh"',
            'file = "instances/knot.ply"',
            f'material = "{material}"',
            "instances = [",
            *steps,
            "]",
        ]
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    tris = write_ply(os.path.join(HERE, "knot.ply"))
    write_scene(os.path.join(HERE, "..", "instances.toml"), tris)
