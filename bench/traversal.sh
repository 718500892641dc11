#!/usr/bin/env bash
# Ray traversal benchmark, Candela's BVH vs Embree 4: see bench/README.md.
#   bench/traversal.sh [REPEATS]   (alternating rounds per scene, default 3)
# 1. The BVH build of 10^6 triangles on 2 threads (RAYON_NUM_THREADS=2).
# 2. Closest-hit and any-hit rays/s on one core (this script pins itself to one CPU) on
#    the Cornell box and on a generated room of 589 836 triangles, Candela and Embree
#    tracing the same diffuse-bounce rays, alternately, in one run.
# 3. The same for Candela alone on `mixed`: a room whose leaf blocks mix analytic spheres
#    and alpha-masked triangles with plain ones (Embree via embreex has triangles only).
# CANDELA_NODES=full|quantized picks the BVH's node layout and CANDELA_LEAVES=inline|indexed
# its leaf layout (default: the library's).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"
repeats="${1:-3}"
"$here/.venv/bin/python" -c 'import embreex, numpy' 2>/dev/null || "$here/setup.sh"
(cd "$root" && cargo build --release -p candela-bench --bin traversal)
example="$root/target/release/traversal"
out="$root/bench/out/traversal"
mkdir -p "$out"
echo "== BVH build, 2 threads"
RAYON_NUM_THREADS=2 "$example" build | tee "$out/build.json"
echo "== traversal, one core"
cpu="$(python3 -c 'import os; print(max(os.sched_getaffinity(0)))')"
taskset -c "$cpu" "$here/.venv/bin/python" "$here/traversal.py" "$example" "$out" "$repeats" cornell room mixed \
    | tee "$out/traversal.md"
