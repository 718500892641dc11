"""Run the `candela` CLI and read back its timing.

`candela render` prints one summary line at the end, e.g.
    512x512, 64 spp, 7.93 s, 2.12 M paths/s, 9.87 M rays/s -> bench/out/candela.exr
where the time covers rendering only (not loading, building the BVH or writing the image).
The whole process is also timed here, so both can be compared with Mitsuba's.
"""

import re
import resource
import subprocess
import time
from dataclasses import dataclass
from typing import Optional

from . import machine

SUMMARY = re.compile(
    r"(?P<w>\d+)x(?P<h>\d+), (?P<spp>\d+) spp, (?P<secs>[\d.]+) s, "
    r"(?P<paths>[\d.]+) M paths/s, (?P<rays>[\d.]+) M rays/s"
)


@dataclass
class CandelaRun:
    command: list
    render_s: float        # from the summary line: the integrator alone
    process_s: float       # the whole process, timed here
    cpu_s: float           # user + system CPU of the whole process, all threads
    mpaths_per_s: float
    mrays_per_s: float
    load_before: str
    load_after: str
    summary: str


def parse_summary(stdout: str) -> Optional[re.Match]:
    found = None
    for line in stdout.splitlines():
        m = SUMMARY.search(line)
        if m:
            found = m
    return found


def run(cmd: list, cwd: Optional[str] = None) -> re.Match:
    """Runs a `candela render` command line and returns its summary line's match; raises
    with candela's output if it failed or printed no summary."""
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    m = parse_summary(p.stdout)
    if p.returncode != 0 or m is None:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr}{p.stdout}")
    return m


def render(binary: str, scene: str, out: str, *, spp: int, max_depth: int, threads: int,
           res: tuple, seed: Optional[int] = None, cwd: Optional[str] = None,
           sampler: Optional[str] = None) -> CandelaRun:
    cmd = [binary, "render", scene, "-o", out, "--spp", str(spp), "--max-depth",
           str(max_depth), "--threads", str(threads), "--res", f"{res[0]}x{res[1]}"]
    if seed is not None:
        cmd += ["--seed", str(seed)]
    if sampler is not None:
        cmd += ["--sampler", sampler]
    load_before = machine.loadavg()
    c0 = _children_cpu_s()
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    process_s = time.perf_counter() - t0
    cpu_s = _children_cpu_s() - c0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr}{p.stdout}")
    m = parse_summary(p.stdout)
    if m is None:
        raise RuntimeError(f"no summary line in candela's output:\n{p.stdout}")
    if (int(m["w"]), int(m["h"]), int(m["spp"])) != (res[0], res[1], spp):
        raise RuntimeError(f"candela rendered {m.group(0)}, not {res[0]}x{res[1]} at {spp} spp")
    return CandelaRun(cmd, float(m["secs"]), process_s, cpu_s, float(m["paths"]),
                      float(m["rays"]),
                      load_before, machine.loadavg(), m.group(0))


def _children_cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime
