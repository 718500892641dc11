#!/usr/bin/env bash
# Interleaved A/B timing of two candela binaries: for each scene, REPEATS rounds of
# A then B, each printing the render time of the summary line (integrator only) and
# the 1-minute load average; then the median of each and B/A.
# Usage: bench/lanes/ab.sh BIN_A BIN_B RES SPP REPEATS SCENE...
set -euo pipefail
a=$1 b=$2 res=$3 spp=$4 reps=$5
shift 5
tmp=$(mktemp -d)
for scene in "$@"; do
    for _ in $(seq "$reps"); do
        for bin in "$a" "$b"; do
            t=$("$bin" render "$scene" -o "$tmp/o.exr" --spp "$spp" --res "${res}x${res}" \
                --threads 2 --seed 0 2>&1 | sed -n 's/.* spp, \([0-9.]*\) s,.*/\1/p')
            echo "$scene $bin $t $(cut -d' ' -f1 /proc/loadavg)"
        done
    done
done | tee "$tmp/log"
python3 - "$tmp/log" "$a" "$b" <<'PY'
import sys, statistics, collections
rows = [l.split() for l in open(sys.argv[1])]
t = collections.defaultdict(list)
for scene, binary, secs, load in rows:
    t[scene, binary].append(float(secs))
for scene in dict.fromkeys(r[0] for r in rows):
    ma, mb = (statistics.median(t[scene, x]) for x in sys.argv[2:4])
    print(f"{scene}: A {ma:.3f} s, B {mb:.3f} s (median), B/A {mb / ma:.3f}")
PY
rm -rf "$tmp"
