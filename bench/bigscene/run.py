"""Big scenes: load, build and render time and peak memory of Candela against Mitsuba 3
on generated height fields (gen_mesh.py) of several sizes, in PLY, OBJ and glTF.

    bench/.venv/bin/python bench/bigscene/run.py [--sizes 2e6,8e6] [--formats ply,obj,glb]
        [--variants llvm_ad_rgb,scalar_rgb] [--threads 2] [--accel auto]

Each row renders the same Mitsuba XML scene (128×128, 4 spp, max depth 3, one constant
sky; glTF: Candela alone, Mitsuba 3 has no glTF loader) in a fresh process, the
renderers alternating. Candela's figures are its own summary line (load / build /
render seconds, peak resident memory, and the peak once loaded: what the load alone
reached, the rest being the build's) and the process's user + system CPU from
/usr/bin/time; Mitsuba's are `load_file` (which builds its BVH) and the first `render`
(JIT compile included for llvm_ad_rgb) timed inside its process, that process's user +
system CPU (Python's import of Mitsuba included) and its peak RSS. On a shared machine
compare CPU seconds and memory: wall times there measure the other tenants. Bytes per
triangle are the whole process's peak over the triangle count. `--accel` is Candela's
leaf layout (auto, inline, compact); `--variants ""` runs Candela alone. The Markdown
table goes to stdout and bench/out/bigscene.md. The instanced scene is gen_instanced.py's.
"""

import argparse
import os
import re
import resource
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BENCH = os.path.dirname(HERE)
REPO = os.path.dirname(BENCH)
sys.path.insert(0, BENCH)

from benchlib import machine, mitsuba_render  # noqa: E402

CANDELA = os.environ.get("CANDELA_BIN", os.path.join(REPO, "target", "release", "candela"))
MESHES = os.path.join(BENCH, "out", "big")
SUMMARY = re.compile(
    r"load (?P<load>[\d.]+) s, build (?P<build>[\d.]+) s, render (?P<render>[\d.]+) s;"
    r".*, (?P<leaves>\w+) leaves\); peak memory (?P<peak>[\d.]+) MB \(load (?P<load_peak>[\d.]+) MB"
)


def candela(scene: str, threads: int, accel: str) -> dict:
    out = os.path.join(BENCH, "out", "bigscene-candela.exr")
    cmd = ["/usr/bin/time", "-f", "TIME %e %U %S %M", CANDELA, "render", scene,
           "--threads", str(threads), "--res", "128x128", "--spp", "4", "--accel", accel,
           "-o", out]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}:\n{p.stderr}")
    m = SUMMARY.search(p.stdout)
    wall, user, sys_, rss_kib = p.stderr.split("TIME ")[1].split()
    return {
        "load": float(m["load"]), "build": float(m["build"]), "render": float(m["render"]),
        "wall": float(wall), "cpu": float(user) + float(sys_), "peak_mb": int(rss_kib) * 1.024e-3,
        "load_peak_mb": float(m["load_peak"]), "leaves": m["leaves"],
    }


def mitsuba(scene: str, variant: str, threads: int) -> dict:
    out = os.path.join(BENCH, "out", f"bigscene-{variant}.exr")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = mitsuba_render.run(scene, out, variant=variant, threads=threads, params={})
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    render = r["renders"][0]
    return {
        "load": r["load_s"], "build": None, "render": render["wall_s"],
        "wall": r["process_s"], "cpu": cpu, "peak_mb": r["peak_rss_mib"] * 1.048576,
        "load_peak_mb": None, "leaves": None,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="2e6,8e6")
    ap.add_argument("--formats", default="ply,obj,glb")
    ap.add_argument("--variants", default="llvm_ad_rgb,scalar_rgb")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--accel", default="auto", help="Candela's --accel: auto, inline, compact")
    a = ap.parse_args()
    info = machine.describe(REPO)
    rows = []
    for size in a.sizes.split(","):
        made = subprocess.run([sys.executable, os.path.join(HERE, "gen_mesh.py"), MESHES, size,
                               "--formats", a.formats], capture_output=True, text=True, check=True)
        triangles = float(size)
        for path in made.stdout.split():
            fmt = path.rsplit(".", 1)[1]
            name = os.path.basename(path)
            xml = path.rsplit(".", 1)[0] + f"-{fmt}.xml"
            scene = xml if os.path.exists(xml) else path
            runs = [("Candela", lambda: candela(scene, a.threads, a.accel))]
            if scene == xml:
                runs += [(f"Mitsuba 3 {v}", lambda v=v: mitsuba(scene, v, a.threads))
                         for v in a.variants.split(",") if v]
            for who, fn in runs:
                r = fn()
                r.update(who=who, mesh=name, per_tri=r["peak_mb"] * 1e6 / triangles,
                         load1=machine.load1())
                rows.append(r)
                print(r, file=sys.stderr, flush=True)

    def f(v, fmt="{:.2f}"):
        return "–" if v is None else fmt.format(v)

    lines = [
        f"Machine: {info['cpu']}, {info['nproc']} cores, {info['memory_gib']} GiB; "
        f"commit {info['git']}; {info['date']}; {a.threads} threads, 128×128, 4 spp; "
        f"Candela --accel {a.accel}.",
        "",
        "| mesh | renderer | load s | build s | load+build s | render s | process wall s "
        "| CPU s | peak MB | peak after load MB | bytes/tri | load avg |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lb = r["load"] + (r["build"] or 0.0)
        who = r["who"] + (f" ({r['leaves']})" if r["leaves"] else "")
        lines.append(
            f"| {r['mesh']} | {who} | {f(r['load'])} | {f(r['build'])} | {f(lb)} "
            f"| {f(r['render'])} | {f(r['wall'])} | {f(r['cpu'])} | {r['peak_mb']:.0f} "
            f"| {f(r['load_peak_mb'], '{:.0f}')} | {r['per_tri']:.0f} | {r['load1']:.1f} |"
        )
    text = "\n".join(lines) + "\n"
    print(text)
    os.makedirs(os.path.join(BENCH, "out"), exist_ok=True)
    with open(os.path.join(BENCH, "out", "bigscene.md"), "w") as fh:
        fh.write(text)


if __name__ == "__main__":
    main()
