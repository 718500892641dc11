"""Writes the big-scene benchmark's instanced scene: one generated height field
(gen_mesh.py's PLY) placed COPIES times on a grid by a TOML `instances` list, so that
the scene renders COPIES × the field's triangles while storing them once.

    python gen_instanced.py OUT_DIR TRIANGLES COPIES

TRIANGLES is the field's (rounded as gen_mesh.py rounds it); the scene is
OUT_DIR/instanced-<COPIES>x<field>.toml, 128×128, 4 spp, max depth 3, a constant sky and
a grey diffuse field, seen from above the grid at an angle. Nothing here is committed
data.
"""

import argparse
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("triangles", type=float)
    ap.add_argument("copies", type=int)
    a = ap.parse_args()
    made = subprocess.run([sys.executable, os.path.join(HERE, "gen_mesh.py"), a.out,
                           str(a.triangles), "--formats", "ply"],
                          capture_output=True, text=True, check=True)
    ply = os.path.basename(made.stdout.split()[0])
    field = ply.removeprefix("field-").removesuffix(".ply")
    cols = math.ceil(math.sqrt(a.copies))
    rows = math.ceil(a.copies / cols)
    # The field spans [-1, 1]² (z up); laid flat (y up), a copy every 2.2 units.
    places = []
    for k in range(a.copies):
        x = (k % cols - (cols - 1) / 2) * 2.2
        z = (k // cols - (rows - 1) / 2) * 2.2
        places.append(f"  [{{ translate = [{x:.2f}, 0, {z:.2f}] }}],")
    extent = 1.1 * max(cols, rows)
    toml = f"""# {a.copies} copies of {ply} ({field} triangles each), written by
# bench/bigscene/gen_instanced.py.
[render]
resolution = [128, 128]
spp = 4
max_depth = 3

[camera]
position = [0, {1.6 * extent:.2f}, {1.9 * extent:.2f}]
look_at = [0, 0, 0]
fov = 40

[environment]
constant = 1.0

[materials.grey]
type = "diffuse"
albedo = 0.5

[[shape]]
type = "mesh"
file = "{ply}"
material = "grey"
transform = [{{ rotate = {{ axis = [1, 0, 0], angle = -90 }} }}]
instances = [
{chr(10).join(places)}
]
"""
    path = os.path.join(a.out, f"instanced-{a.copies}x{field}.toml")
    with open(path, "w") as fh:
        fh.write(toml)
    print(path)


if __name__ == "__main__":
    main()
