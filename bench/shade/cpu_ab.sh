#!/usr/bin/env bash
# CPU time per sample (user + system, all threads, the whole process) of two Candela
# binaries on issue 35's seven acceptance scenes, interleaved over rounds so that both
# see the same machine load; prints each scene's medians and NEW ÷ OLD.
# Usage: bench/shade/cpu_ab.sh OLD NEW [RES] [SPP] [ROUNDS] [THREADS]
set -euo pipefail
old=$1 new=$2 res=${3:-128} spp=${4:-64} rounds=${5:-3} threads=${6:-2}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
scenes=(spot-point-room glossy-plates hdr-sky-sun thin-lens many-lights cornell-textured
    sun-sky-glass)
for ((r = 0; r < rounds; r++)); do
    for s in "${scenes[@]}"; do
        for which in old new; do
            bin=$old
            [[ $which == new ]] && bin=$new
            /usr/bin/time -f "%U %S" -o "$tmp/t" "$bin" render "$here/../scenes/$s.xml" \
                -o "$tmp/out.exr" --spp "$spp" --res "${res}x${res}" --threads "$threads" \
                >/dev/null 2>&1
            echo "$s $which $(cat "$tmp/t")" >> "$tmp/all"
        done
    done
done
python3 - "$tmp/all" "$((res * res * spp))" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
n = int(sys.argv[2])
t = {}
for s, w, u, k in rows:
    t.setdefault((s, w), []).append((float(u) + float(k)) * 1e9 / n)
print("| scene | old ns/sample | new ns/sample | new ÷ old |")
print("|---|--:|--:|--:|")
for s in dict.fromkeys(r[0] for r in rows):
    a, b = statistics.median(t[(s, "old")]), statistics.median(t[(s, "new")])
    print(f"| {s} | {a:.0f} | {b:.0f} | {b / a:.2f} |")
PY
rm -rf "$tmp"
