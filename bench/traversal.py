"""Candela's BVH against Embree 4 (via embreex) on the same diffuse-bounce rays: rays per
second on one core for closest hit and any hit, and whether both found the same triangle.
Run by bench/traversal.sh, which pins this process (and so Candela's) to one core.

Usage: traversal.py CANDELA_EXAMPLE OUT_DIR REPEATS SCENE [SCENE ...]. For each scene,
REPEATS rounds alternate a Candela run (`traversal rays SCENE OUT_DIR/SCENE`, which writes
the triangles and rays and times its own queries, best of 3) with Embree's timing of the
same queries (best of 3); the best of all rounds is kept for each, so that both sides
see the same machine load.

A scene with spheres or alpha-masked triangles (`mixed`) is Candela's alone (embreex has
triangles only, and no filter callbacks): its REPEATS runs go to a second table, a
regression guard for blocks that mix primitive kinds."""
import json
import os
import subprocess
import sys
import time

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh


def best_of(runs, f):
    """The fastest of `runs` timings of f() and its last result."""
    best, out = float("inf"), None
    for _ in range(runs):
        t = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t)
    return best, out


def run_candela(example, scene, folder):
    out = subprocess.run([example, "rays", scene, folder], check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def bench_candela_only(example, scene, folder, repeats, candela):
    """Best rays/s of REPEATS Candela runs of a scene Embree cannot trace."""
    for _ in range(repeats - 1):
        again = run_candela(example, scene, folder)
        for k in ("closest_mrays_s", "any_mrays_s"):
            candela[k] = max(candela[k], again[k])
        candela["build_s"] = min(candela["build_s"], again["build_s"])
    return candela


def bench(example, scene, folder, repeats):
    candela = run_candela(example, scene, folder)
    if candela.get("spheres", 0) or candela.get("masked", 0):
        return bench_candela_only(example, scene, folder, repeats, candela)
    tris = np.fromfile(f"{folder}/tris.f32", dtype=np.float32).reshape(-1, 3, 3)
    rays = np.fromfile(f"{folder}/rays.f32", dtype=np.float32).reshape(-1, 6)
    o, d = np.ascontiguousarray(rays[:, :3]), np.ascontiguousarray(rays[:, 3:])
    hits = np.fromfile(f"{folder}/candela_hits.bin", dtype=np.dtype([("prim", "<u4"), ("t", "<f4")]))
    t = time.perf_counter()
    embree = rtcore_scene.EmbreeScene()
    TriangleMesh(embree, tris)
    embree.run(o[:1], d[:1])  # Embree builds its BVH on the first query.
    build_s = time.perf_counter() - t
    closest_s, res = best_of(3, lambda: embree.run(o, d, output=1))
    any_s, occ = best_of(3, lambda: embree.run(o, d, query="OCCLUDED"))
    for _ in range(repeats - 1):
        again = run_candela(example, scene, folder)
        for k in ("closest_mrays_s", "any_mrays_s"):
            candela[k] = max(candela[k], again[k])
        closest_s = min(closest_s, best_of(3, lambda: embree.run(o, d, output=1))[0])
        any_s = min(any_s, best_of(3, lambda: embree.run(o, d, query="OCCLUDED"))[0])
    n = len(o)
    prim = res["primID"].astype(np.int64)
    c_prim = np.where(hits["prim"] == 0xFFFFFFFF, -1, hits["prim"].astype(np.int64))
    both = (prim >= 0) & (c_prim >= 0)
    rel = np.abs(res["tfar"][both] - hits["t"][both]) / np.maximum(hits["t"][both], 1e-30)
    return {
        "scene": scene,
        "embree": True,
        "simd": candela.get("simd", "?"),
        "triangles": len(tris),
        "rays": n,
        "candela_build_s": candela["build_s"],
        "embree_build_s": build_s,
        "candela_closest": candela["closest_mrays_s"],
        "embree_closest": n / closest_s / 1e6,
        "candela_any": candela["any_mrays_s"],
        "embree_any": n / any_s / 1e6,
        "same_hit_or_miss": float(np.mean((prim >= 0) == (c_prim >= 0))),
        "same_triangle": float(np.mean(prim[both] == c_prim[both])) if both.any() else 1.0,
        "t_rel_err_p99": float(np.quantile(rel, 0.99)) if both.any() else 0.0,
        "embree_occluded_agree": float(np.mean((np.asarray(occ) != -1) == (c_prim >= 0))),
    }


def main():
    example, out, repeats, scenes = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4:]
    rows = []
    for scene in scenes:
        folder = os.path.join(out, scene)
        os.makedirs(folder, exist_ok=True)
        rows.append(bench(example, scene, folder, repeats))
    peers = [r for r in rows if r.get("embree")]
    alone = [r for r in rows if not r.get("embree")]
    print(f"cores this process may use: {sorted(os.sched_getaffinity(0))}; "
          f"{repeats} alternating rounds, best of each side; "
          f"Candela's kernels: {', '.join(sorted({r['simd'] for r in rows}))}")
    print()
    if peers:
        print("| scene | triangles | rays | Candela closest (M rays/s) | Embree closest | ratio "
              "| Candela any-hit | Embree any-hit | ratio | same hit/miss | same triangle | build Candela / Embree (s) |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in peers:
        print(f"| {r['scene']} | {r['triangles']} | {r['rays']} | {r['candela_closest']:.2f} | "
              f"{r['embree_closest']:.2f} | {r['candela_closest'] / r['embree_closest']:.2f} | "
              f"{r['candela_any']:.2f} | {r['embree_any']:.2f} | {r['candela_any'] / r['embree_any']:.2f} | "
              f"{r['same_hit_or_miss']:.5f} | {r['same_triangle']:.5f} | "
              f"{r['candela_build_s']:.3f} / {r['embree_build_s']:.3f} |")
    print()
    if alone:
        print("Candela only (spheres and alpha masks; no Embree peer):")
        print()
        print("| scene | triangles | spheres | alpha-masked | rays | Candela closest (M rays/s) "
              "| Candela any-hit | hit | build (s) |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in alone:
        print(f"| {r['scene']} | {r['triangles']} | {r['spheres']} | {r['masked']} | {r['rays']} | "
              f"{r['closest_mrays_s']:.2f} | {r['any_mrays_s']:.2f} | {r['hit']} | {r['build_s']:.3f} |")
    if alone:
        print()
    with open(os.path.join(out, "traversal.json"), "w") as f:
        json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
