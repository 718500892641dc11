"""Generates the big-scene benchmark's meshes: a height field over a regular grid of
n × n quads (2n² triangles, (n+1)² vertices, positions only), written as binary
little-endian PLY, Wavefront OBJ and binary glTF (GLB), plus a Mitsuba 3 XML scene per
file that both Candela and Mitsuba read (a camera above the field, a constant sky, a
diffuse grey surface).

    python gen_mesh.py OUT_DIR TRIANGLES [--formats ply,obj,glb]

TRIANGLES is rounded to the nearest 2n² (2M → n = 1000, 8M → 2000, 32M → 4000).
Nothing here is committed data: the files are made where the benchmark runs.
"""

import argparse
import json
import math
import os
import struct

import numpy as np


def grid(n: int):
    """Positions ((n+1)², 3) float32 and triangles (2n², 3) uint32 of the height field."""
    t = np.linspace(-1.0, 1.0, n + 1, dtype=np.float32)
    x, y = np.meshgrid(t, t, indexing="xy")
    z = 0.05 * np.sin(9.0 * x) * np.cos(7.0 * y) + 0.02 * np.sin(31.0 * (x + y))
    pos = np.stack([x, y, z.astype(np.float32)], axis=-1).reshape(-1, 3)
    i = np.arange(n, dtype=np.uint32)
    row, col = np.meshgrid(i, i, indexing="ij")
    v0 = (row * (n + 1) + col).reshape(-1)
    v1, v2, v3 = v0 + 1, v0 + n + 2, v0 + n + 1
    tris = np.empty((2 * n * n, 3), dtype=np.uint32)
    tris[0::2] = np.stack([v0, v1, v2], axis=-1)
    tris[1::2] = np.stack([v0, v2, v3], axis=-1)
    return pos, tris


def write_ply(path, pos, tris):
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(pos)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(tris)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    faces = np.empty(len(tris), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"] = 3
    faces["i"] = tris
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(pos.astype("<f4").tobytes())
        f.write(faces.tobytes())


def write_obj(path, pos, tris, chunk=1 << 20):
    with open(path, "w") as f:
        for s in range(0, len(pos), chunk):
            p = pos[s : s + chunk]
            f.write("".join("v %.6g %.6g %.6g\n" % tuple(v) for v in p.tolist()))
        for s in range(0, len(tris), chunk):
            t = tris[s : s + chunk] + 1
            f.write("".join("f %d %d %d\n" % tuple(v) for v in t.tolist()))


def write_glb(path, pos, tris):
    pbytes = pos.astype("<f4").tobytes()
    ibytes = tris.astype("<u4").tobytes()
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(pbytes) + len(ibytes)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pbytes), "target": 34962},
            {"buffer": 0, "byteOffset": len(pbytes), "byteLength": len(ibytes), "target": 34963},
        ],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": len(pos),
                "type": "VEC3",
                "min": pos.min(axis=0).tolist(),
                "max": pos.max(axis=0).tolist(),
            },
            {"bufferView": 1, "componentType": 5125, "count": tris.size, "type": "SCALAR"},
        ],
    }
    js = json.dumps(gltf).encode()
    js += b" " * (-len(js) % 4)
    body = pbytes + ibytes
    total = 12 + 8 + len(js) + 8 + len(body)
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, total))
        f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
        f.write(struct.pack("<II", len(body), 0x004E4942) + body)


XML = """<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, -2.6, 2.2" target="0, 0, 0" up="0, 0, 1"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="128"/><integer name="height" value="128"/>
      <rfilter type="box"/></film>
  </sensor>
  <emitter type="constant"><rgb name="radiance" value="1.0"/></emitter>
  <shape type="{kind}"><string name="filename" value="{file}"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
</scene>
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("triangles", type=float)
    ap.add_argument("--formats", default="ply,obj,glb")
    a = ap.parse_args()
    n = max(1, round(math.sqrt(a.triangles / 2)))
    os.makedirs(a.out, exist_ok=True)
    pos, tris = grid(n)
    tag = f"{2 * n * n / 1e6:g}M"
    for fmt in a.formats.split(","):
        path = os.path.join(a.out, f"field-{tag}.{fmt}")
        if not os.path.exists(path):
            {"ply": write_ply, "obj": write_obj, "glb": write_glb}[fmt](path + ".tmp", pos, tris)
            os.replace(path + ".tmp", path)
        if fmt in ("ply", "obj"):
            with open(os.path.join(a.out, f"field-{tag}-{fmt}.xml"), "w") as f:
                f.write(XML.format(kind=fmt, file=os.path.basename(path)))
        print(path)


if __name__ == "__main__":
    main()
