#!/usr/bin/env bash
# Instructions per camera path (callgrind, deterministic; unaffected by other load):
# (I(spp=hi) - I(spp=lo)) / (res² · (hi - lo)), so that scene loading and the BVH
# build cancel. Usage: bench/lanes/ipp.sh BINARY SCENE [RES] [LO] [HI] [extra args…]
set -euo pipefail
bin=$1 scene=$2 res=${3:-64} lo=${4:-1} hi=${5:-3}
shift $(( $# < 5 ? $# : 5 ))
tmp=$(mktemp -d)
count() {
    local spp=$1
    shift
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg" "$bin" render "$scene" \
        -o "$tmp/out.exr" --spp "$spp" --res "${res}x${res}" --threads 1 --seed 1 "$@" 2>&1 \
        | sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
a=$(count "$lo" "$@")
b=$(count "$hi" "$@")
rm -rf "$tmp"
python3 -c "print(f'{($b - $a) / ($res * $res * ($hi - $lo)):.0f}')"
