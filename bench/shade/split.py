#!/usr/bin/env python3
"""Where a render's instructions go, by stage of the path: reads callgrind files and sums
each instruction's cost under the stage its *source* file belongs to (inlined code counts
where it was written, not where it was inlined), so `path.rs` inlined into the render
loop still counts as the loop and `exact_sum.rs` inlined into the splat as the film.

Math-library leaves (libm's expf, compiler-builtins' rint or f64→i128) count for the
stage of the code that called them. Code of std/core inlined into a Candela function
counts for that function's module.

Usage: split.py LO.cg HI.cg PATHS  — prints the stages' instructions per camera path,
(HI − LO) / PATHS, so that scene loading and the BVH build cancel.
"""
import re
import sys
from collections import defaultdict

# (stage, patterns on the source path or, for library code, the function's name)
STAGES = [
    ("traversal", ["/accel/", "/bvh/", "candela-core/src/scene/mod.rs", "instance.rs",
                   "candela-core/src/geometry.rs", "candela-core/src/scene/shadow.rs",
                   "candela-core/src/scene/coherent.rs",
                   "candela_core::accel", "candela_core::bvh", "candela_core::scene::Scene::"]),
    ("hit record", ["scene/interaction.rs", "scene/mesh.rs", "alpha.rs",
                    "candela_core::scene::interaction"]),
    ("film/splat", ["splat.rs", "film.rs", "exact_sum.rs", "filter.rs", "limb_sums.rs", "lane_expf.rs", "candela_core::splat",
                    "candela_core::film"]),
    ("sampler", ["/sampler/", "candela_core::sampler"]),
    ("camera", ["/camera/", "candela_core::camera"]),
    ("light sampler", ["/light_sampler/", "candela_core::light_sampler", "light/bounds.rs",
                       "candela_core::light::bounds", "light/importance_lanes.rs",
                       "candela_core::light::importance_lanes"]),
    ("lights", ["/light/", "candela_core::light"]),
    ("BSDF+texture", ["/bsdf/", "material.rs", "texture.rs", "candela_core::bsdf",
                      "candela_core::material", "candela_core::texture"]),
    ("path loop", ["/integrator/", "candela_core::integrator", "sampling.rs", "math.rs"]),
    ("scheduling", ["rayon", "candela_core::splat::render_pass"]),
]


def stage_of(text):
    for stage, pats in STAGES:
        if any(p in text for p in pats):
            return stage
    return None


LIB_OBJ = re.compile(r"libm\.so|libc\.so")
LIB_FILE = re.compile(r"compiler-builtins|/libm[-/]|sysdeps/ieee754")
# Leaves of the math runtime by name: `__fixdfti`, `rint`, `expf`, `libm::…`.
LIB_FN = re.compile(r"^(__[a-z0-9_]+|[a-z0-9]+|libm::.*|compiler_builtins::.*)$")


DEBUG = False


def resolve(names, kind, rest):
    """The name a callgrind line `kind=rest` gives: `(id) text` defines id in the table of
    its kind (files, functions, objects; `names` holds the three), `(id)` refers to it."""
    m = re.match(r"\((\d+)\)(?: (.*))?", rest)
    if not m:
        return rest
    table = names["fl" if kind in ("fl", "fi", "fe", "cfi", "cfl") else kind.lstrip("c")]
    if m.group(2) is not None:
        table[m.group(1)] = m.group(2)
    return table.get(m.group(1), "?")


def is_lib_name(ob, fl, fn):
    """Whether code of object `ob`, file `fl`, function `fn` is a math-runtime leaf."""
    return bool(LIB_OBJ.search(ob or "") or LIB_FILE.search(fl or "")
                or LIB_FN.match(fn or ""))


def split(path):
    others = defaultdict(int)
    names = {"fl": {}, "fn": {}, "ob": {}}
    cost = defaultdict(int)
    cur = {"ob": "", "fl": "", "fi": None, "fn": ""}
    call_ob = call_fl = call_fn = None
    pending_call = False

    def name(kind, rest):
        return resolve(names, kind, rest)

    def here(v):
        f = cur["fi"] or cur["fl"]
        if "candela-" in f:
            s = stage_of(f)
        else:
            s = stage_of(cur["fn"])
        if s is None:
            s = "other"
        if DEBUG:
            others[(s, f.split("/src/")[-1], cur["fn"][-60:])] += v
        return s

    with open(path) as fh:
        for line in fh:
            if not line or line[0] == "#":
                continue
            c = line[0]
            if c.isdigit() or c in "+-*":
                parts = line.split()
                if len(parts) < 2:
                    continue
                v = int(parts[1])
                if pending_call:
                    pending_call = False
                    target = (call_ob or cur["ob"], call_fl or "", call_fn)
                    call_ob = call_fl = call_fn = None
                    # A call's inclusive cost: a library leaf counts for its caller.
                    if is_lib_name(*target):
                        if not is_lib_name(cur["ob"], cur["fl"], cur["fn"]):
                            cost[here(v)] += v
                    continue
                if is_lib_name(cur["ob"], cur["fl"], cur["fn"]):
                    continue  # counted at the call site
                cost[here(v)] += v
                continue
            key, _, rest = line.rstrip("\n").partition("=")
            if key == "ob":
                cur["ob"] = name("ob", rest)
            elif key == "fl":
                cur["fl"] = name("fl", rest)
                cur["fi"] = None
            elif key in ("fi", "fe"):
                f = name(key, rest)
                cur["fi"] = None if f == cur["fl"] else f
            elif key == "fn":
                cur["fn"] = name("fn", rest)
                cur["fi"] = None
            elif key == "cob":
                call_ob = name("ob", rest)
            elif key in ("cfi", "cfl"):
                call_fl = name(key, rest)
            elif key == "cfn":
                call_fn = name("fn", rest)
            elif key == "calls":
                pending_call = True
            elif key in ("jump", "jcnd"):
                pass
    return cost, others


def main():
    global DEBUG
    DEBUG = len(sys.argv) > 4
    lo, hi, paths = sys.argv[1], sys.argv[2], float(sys.argv[3])
    (a, oa), (b, ob) = split(lo), split(hi)
    stages = [s for s, _ in STAGES] + ["other"]
    total = 0.0
    rows = []
    for s in stages:
        d = (b.get(s, 0) - a.get(s, 0)) / paths
        total += d
        rows.append((s, d))
    for s, d in rows:
        print(f"{s:14s} {d:8.0f}  {100 * d / total:5.1f} %")
    print(f"{'total':14s} {total:8.0f}")
    if DEBUG:
        diff = {k: (ob[k] - oa.get(k, 0)) / paths for k in ob}
        for k, v in sorted(diff.items(), key=lambda kv: -kv[1])[:30]:
            print(f"{v:8.1f}", k)


if __name__ == "__main__":
    main()
