#!/usr/bin/env bash
# Instructions per camera path and where they go (bench/shade/split.py's stages), by
# callgrind (deterministic; unaffected by other load), one thread, seed 1: two renders
# at LO and HI spp, differenced so that scene loading and the BVH build cancel.
# Usage: bench/shade/split.sh BINARY SCENE [RES] [LO] [HI] [extra render args…]
# INLINE=1 counts inlined library code where it was inlined from rather than by the
# function it ends up in (per-instruction data, bench/shade/split_inline.py).
set -euo pipefail
bin=$1 scene=$2 res=${3:-48} lo=${4:-1} hi=${5:-5}
shift $(( $# < 5 ? $# : 5 ))
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
for spp in "$lo" "$hi"; do
    valgrind --tool=callgrind ${INLINE:+--dump-instr=yes} --callgrind-out-file="$tmp/$spp.cg" \
        "$bin" render "$scene" \
        -o "$tmp/out.exr" --spp "$spp" --res "${res}x${res}" --threads 1 --seed 1 "$@" \
        >/dev/null 2>&1
done
paths=$((res * res * (hi - lo)))
if [[ -n ${INLINE:-} ]]; then
    python3 "$here/split_inline.py" "$bin" "$tmp/$lo.cg" "$tmp/$hi.cg" "$paths"
else
    python3 "$here/split.py" "$tmp/$lo.cg" "$tmp/$hi.cg" "$paths"
fi
rm -rf "$tmp"
