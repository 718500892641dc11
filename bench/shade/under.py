#!/usr/bin/env python3
"""The instructions a path spends inside one inlined function, by the stage and source
line of each instruction's innermost frame: what `frames.py` gives a stage, for a
function instead (e.g. `Scene::unoccluded`, a shadow ray's set-up inlined into the loop).

Reads two callgrind files made with `--dump-instr=yes` (as `frames.sh` makes them), takes
each instruction address's cost per camera path ((HI − LO) / PATHS), asks
`llvm-addr2line -i` for its chain of inlined frames, and keeps the addresses one of whose
frames' function names contains FUNC (or one of its `|`-separated alternatives).

Usage: under.py BINARY LO.cg HI.cg PATHS FUNC [LINES] [--asm]
With --asm, also the kept instructions themselves (`objdump -d`), by address, with their
cost a path and innermost source line.
"""
import os
import re
import subprocess
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from frames import inline_frames, instruction_costs  # noqa: E402
from split import stage_of  # noqa: E402


def main():
    binary, lo, hi, paths, func = sys.argv[1:6]
    asm = "--asm" in sys.argv
    args = [a for a in sys.argv[6:] if a != "--asm"]
    lines = int(args[0]) if args else 30
    (a, _), (b, _) = instruction_costs(lo), instruction_costs(hi)
    rows = [(addr, (v - a.get(addr, 0)) / float(paths)) for addr, v in b.items()]
    rows = [(addr, d) for addr, d in rows if abs(d) >= 1e-3]
    frames = inline_frames(binary, [addr for addr, _ in rows])
    by_stage = defaultdict(float)
    by_line = defaultdict(float)
    by_file = defaultdict(float)
    total = 0.0
    kept = []
    for addr, d in rows:
        chain = frames.get(addr, [])
        if not any(f in fn for fn, _ in chain for f in func.split("|")):
            continue
        total += d
        kept.append((addr, d, chain))
        inner = next((loc for _, loc in chain if "candela-" in loc), "?")
        by_stage[stage_of(inner) or "other"] += d
        by_line[inner.split("/src/")[-1]] += d
        by_file[inner.split("/src/")[-1].split(":")[0]] += d
    print(f"inside {func}: {total:.0f} instructions a path")
    for s, v in sorted(by_stage.items(), key=lambda kv: -kv[1]):
        print(f"  {s:14s} {v:8.1f}")
    print("by source file:")
    for f, v in sorted(by_file.items(), key=lambda kv: -kv[1]):
        print(f"  {v:8.1f} {f}")
    print("by source line:")
    for loc, v in sorted(by_line.items(), key=lambda kv: -kv[1])[:lines]:
        print(f"  {v:8.1f} {loc}")
    if asm and kept:
        print_asm(binary, kept)


def print_asm(binary, kept):
    """The kept instructions, in address order, with cost and innermost source line."""
    lo, hi = min(a for a, _, _ in kept), max(a for a, _, _ in kept)
    out = subprocess.run(["objdump", "-d", "--no-show-raw-insn", f"--start-address={lo:#x}",
                          f"--stop-address={hi + 1:#x}", binary],
                         capture_output=True, text=True, check=True).stdout
    text = {}
    for ln in out.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s*(.*)", ln)
        if m:
            text[int(m.group(1), 16)] = m.group(2)
    for addr, d, chain in sorted(kept):
        inner = next((loc for _, loc in chain if "candela-" in loc), "?").split("/src/")[-1]
        print(f"  {addr:#x} {d:6.2f}  {text.get(addr, '?'):48s} {inner}")


if __name__ == "__main__":
    main()
