#!/usr/bin/env bash
# Instructions a camera path spends inside inlined function(s) FUNC (bench/shade/under.py),
# by the stage and source line of each instruction's innermost frame: callgrind with
# --dump-instr=yes, one thread, seed 1, LO and HI spp differenced as in split.sh.
# Usage: bench/shade/under.sh BINARY SCENE "FUNC [FUNC…]" [RES] [LO] [HI]
#   (FUNC e.g. "Scene::unoccluded", matched within the inlined frames' names; "A|B" counts
#   an instruction inside A or B once). ASM=1 also lists the instructions.
set -euo pipefail
bin=$1 scene=$2 funcs=$3 res=${4:-48} lo=${5:-1} hi=${6:-5}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
for spp in "$lo" "$hi"; do
    valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file="$tmp/$spp.cg" "$bin" \
        render "$scene" -o "$tmp/out.exr" --spp "$spp" --res "${res}x${res}" --threads 1 \
        --seed 1 >/dev/null 2>&1
done
for f in $funcs; do
    python3 "$here/under.py" "$bin" "$tmp/$lo.cg" "$tmp/$hi.cg" "$((res * res * (hi - lo)))" "$f" 30 ${ASM:+--asm}
done
rm -rf "$tmp"
