#!/usr/bin/env python3
"""What a stage of bench/shade/split.py really holds: split.py counts std and glam code by
the function it is inlined into, so arithmetic of the BSDF or the sampler inlined into
the render loop counts as "path loop". This reads two callgrind files made with
`--dump-instr=yes`, takes each instruction address's cost per camera path
((HI − LO) / PATHS), keeps the addresses split.py gives STAGE, and asks
`llvm-addr2line -i` for each one's chain of inlined frames: the innermost frame in a
Candela source file names the stage the instruction really serves.

Usage: frames.py BINARY LO.cg HI.cg PATHS STAGE [LINES]
Prints the real stages of STAGE's instructions, then (LINES, default 30) the source lines
of the instructions that really are STAGE's, costliest first.
"""
import os
import re
import subprocess
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from split import stage_of  # noqa: E402


def instruction_costs(path):
    """Self cost of each instruction address, and its function and source file."""
    names = {"fl": {}, "fn": {}, "ob": {}}
    cost = defaultdict(int)
    where = {}
    cur = {"fl": "", "fi": None, "fn": ""}
    addr = line = 0
    after_call = False

    def name(table, rest):
        m = re.match(r"\((\d+)\)(?: (.*))?", rest)
        if not m:
            return rest
        if m.group(2) is not None:
            names[table][m.group(1)] = m.group(2)
        return names[table].get(m.group(1), "?")

    def position(tok, prev):
        if tok == "*":
            return prev
        if tok[0] in "+-":
            return prev + int(tok, 0)
        return int(tok, 0)

    with open(path) as fh:
        for ln in fh:
            c = ln[:1]
            if c.isdigit() or c in "+-*":
                parts = ln.split()
                if len(parts) < 3:
                    continue
                addr, line = position(parts[0], addr), position(parts[1], line)
                if after_call:  # a call's inclusive cost, not this instruction's
                    after_call = False
                    continue
                cost[addr] += int(parts[2])
                where[addr] = (cur["fn"], cur["fi"] or cur["fl"])
                continue
            key, _, rest = ln.rstrip("\n").partition("=")
            if key == "fl":
                cur["fl"], cur["fi"] = name("fl", rest), None
            elif key in ("fi", "fe"):
                f = name("fl", rest)
                cur["fi"] = None if f == cur["fl"] else f
            elif key == "fn":
                cur["fn"], cur["fi"] = name("fn", rest), None
            elif key in ("cfi", "cfl"):
                name("fl", rest)
            elif key == "cfn":
                name("fn", rest)
            elif key in ("ob", "cob"):
                name("ob", rest)
            elif key == "calls":
                after_call = True
    return cost, where


def split_stage(fn, source):
    """The stage split.py gives an instruction (by file, else by function)."""
    s = stage_of(source) if "candela-" in source else stage_of(fn)
    return s or "other"


def inline_frames(binary, addresses):
    """{address: [(function, file:line) of each inlined frame, innermost first]}, from the
    binary's debug information by `llvm-addr2line -i -f`."""
    query = "".join(f"{addr:#x}\n" for addr in addresses)
    out = subprocess.run(["llvm-addr2line", "-i", "-f", "-C", "-a", "-e", binary],
                         input=query, capture_output=True, text=True, check=True).stdout
    frames, cur = {}, None
    it = iter(out.splitlines())
    for ln in it:
        if ln.startswith("0x"):
            cur = int(ln, 16)
            frames[cur] = []
        else:
            frames[cur].append((ln, next(it)))  # the function line, then its file:line
    return frames


def main():
    binary, lo, hi, paths, stage = sys.argv[1:6]
    lines = int(sys.argv[6]) if len(sys.argv) > 6 else 30
    (a, _), (b, where) = instruction_costs(lo), instruction_costs(hi)
    rows = []
    for addr, v in b.items():
        d = (v - a.get(addr, 0)) / float(paths)
        if abs(d) >= 1e-3 and split_stage(*where[addr]) == stage:
            rows.append((addr, d))
    frames = inline_frames(binary, [addr for addr, _ in rows])
    real = defaultdict(float)
    by_line = defaultdict(float)
    for addr, d in rows:
        inner = next((loc for _, loc in frames.get(addr, []) if "candela-" in loc), "?")
        s = stage_of(inner) or "other"
        real[s] += d
        if s == stage:
            by_line[inner.split("/src/")[-1]] += d
    print(f"{stage} by split.py: {sum(d for _, d in rows):.0f} instructions a path")
    for s, v in sorted(real.items(), key=lambda kv: -kv[1]):
        print(f"  {s:14s} {v:8.1f}")
    print(f"{stage}'s own source lines:")
    for loc, v in sorted(by_line.items(), key=lambda kv: -kv[1])[:lines]:
        print(f"  {v:8.1f} {loc}")


if __name__ == "__main__":
    main()
