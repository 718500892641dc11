#!/usr/bin/env bash
# What a stage of bench/shade/split.sh really holds, by each instruction's innermost
# inlined source frame (bench/shade/frames.py): callgrind with --dump-instr=yes, one
# thread, seed 1, LO and HI spp differenced as in split.sh.
# Usage: bench/shade/frames.sh BINARY SCENE STAGE [RES] [LO] [HI]   (STAGE e.g. "path loop")
set -euo pipefail
bin=$1 scene=$2 stage=$3 res=${4:-48} lo=${5:-1} hi=${6:-5}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
for spp in "$lo" "$hi"; do
    valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file="$tmp/$spp.cg" "$bin" \
        render "$scene" -o "$tmp/out.exr" --spp "$spp" --res "${res}x${res}" --threads 1 \
        --seed 1 >/dev/null 2>&1
done
python3 "$here/frames.py" "$bin" "$tmp/$lo.cg" "$tmp/$hi.cg" "$((res * res * (hi - lo)))" \
    "$stage"
rm -rf "$tmp"
