#!/usr/bin/env python3
"""Where a render's instructions go, by stage (bench/shade/split.py's stages), with inlined
library code counted where it was inlined *from*: reads callgrind files written with
`--dump-instr=yes`, takes each instruction's inline chain from the binary's debug
information (`addr2line -i`), and counts the instruction for the innermost Candela source
file in that chain. `split.py` counts std, stdarch and glam code under the Candela
*function* it ends up in, so that an intrinsic of the light sampler inlined into the
render loop counts as the path loop; here it counts as the light sampler.

Library leaves (libm's `expf`, compiler-builtins) count for the Candela line that calls
them, as in split.py. An instruction with no Candela file in its chain (a std function
compiled on its own) counts by its callgrind function name, as in split.py.

Usage: split_inline.py BINARY LO.cg HI.cg PATHS  — prints the stages' instructions per
camera path, (HI − LO) / PATHS (`INLINE=1 bench/shade/split.sh`).
"""
import subprocess
import sys
from collections import defaultdict

from split import STAGES, is_lib_name, resolve, stage_of


def costs_by_address(path):
    """{(address, callgrind function name): instructions} of the binary's own code, a
    library callee's inclusive cost added at its call site."""
    names = {"fl": {}, "fn": {}, "ob": {}}
    cur = {"ob": "", "fl": "", "fn": ""}
    call = {"ob": None, "fl": None, "fn": None}
    pending_call = False
    addr = 0
    line_no = 0
    out = defaultdict(int)

    def name(kind, rest):
        return resolve(names, kind, rest)

    def position(field, last, base):
        if field == "*":
            return last
        if field[0] in "+-":
            return last + int(field, 0)
        return int(field, base)

    with open(path) as fh:
        for raw in fh:
            line = raw.rstrip("\n")
            if not line or line[0] == "#":
                continue
            c = line[0]
            if c.isdigit() or c in "+-*":
                parts = line.split()
                if len(parts) < 3:
                    continue
                addr = position(parts[0], addr, 16)
                line_no = position(parts[1], line_no, 10)
                v = int(parts[2])
                here_lib = is_lib_name(cur["ob"], cur["fl"], cur["fn"])
                if pending_call:
                    pending_call = False
                    target = (call["ob"] or cur["ob"], call["fl"] or "", call["fn"])
                    call = {"ob": None, "fl": None, "fn": None}
                    if is_lib_name(*target) and not here_lib:
                        out[(addr, cur["fn"])] += v
                    continue
                if not here_lib:
                    out[(addr, cur["fn"])] += v
                continue
            key, _, rest = line.partition("=")
            if key == "ob":
                cur["ob"] = name("ob", rest)
            elif key == "fl":
                cur["fl"] = name("fl", rest)
            elif key in ("fi", "fe"):
                name(key, rest)
            elif key == "fn":
                cur["fn"] = name("fn", rest)
            elif key == "cob":
                call["ob"] = name(key, rest)
            elif key in ("cfi", "cfl"):
                call["fl"] = name(key, rest)
            elif key == "cfn":
                call["fn"] = name(key, rest)
            elif key == "calls":
                pending_call = True
    return out


def inline_files(binary, addresses):
    """{address: [source file of each frame, innermost first]} by `addr2line -a -i`."""
    addresses = sorted(addresses)
    text = subprocess.run(
        ["addr2line", "-a", "-i", "-e", binary],
        input="\n".join(hex(a) for a in addresses),
        capture_output=True, text=True, check=True).stdout
    chains = {}
    current = None
    for line in text.splitlines():
        if line.startswith("0x"):
            current = int(line, 16)
            chains[current] = []
        elif current is not None:
            chains[current].append(line.rsplit(":", 1)[0])
    return chains


def split(binary, path, chains):
    costs = costs_by_address(path)
    missing = {a for a, _ in costs if a not in chains}
    if missing:
        chains.update(inline_files(binary, missing))
    stage = defaultdict(int)
    for (a, fn), v in costs.items():
        s = None
        for f in chains.get(a, []):
            if "candela-" in f:
                s = stage_of(f) or "other"
                break
        if s is None:
            s = stage_of(fn) or "other"
        stage[s] += v
    return stage


def main():
    binary, lo, hi, paths = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
    chains = {}
    a, b = split(binary, lo, chains), split(binary, hi, chains)
    stages = [s for s, _ in STAGES] + ["other"]
    rows = [(s, (b.get(s, 0) - a.get(s, 0)) / paths) for s in stages]
    total = sum(d for _, d in rows)
    for s, d in rows:
        print(f"{s:14s} {d:8.0f}  {100 * d / total:5.1f} %")
    print(f"{'total':14s} {total:8.0f}")


if __name__ == "__main__":
    main()
