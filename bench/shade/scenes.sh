#!/usr/bin/env bash
# The cost split (bench/shade/split.sh) of one binary on issue 35's seven acceptance
# scenes, two at a time. Usage: bench/shade/scenes.sh BINARY [RES] [LO] [HI]
# INLINE=1 counts inlined library code where it was inlined from (see split.sh).
set -euo pipefail
bin=$1 res=${2:-48} lo=${3:-1} hi=${4:-5}
here=$(cd "$(dirname "$0")" && pwd)
scenes=(spot-point-room glossy-plates hdr-sky-sun thin-lens many-lights cornell-textured
    sun-sky-glass)
tmp=$(mktemp -d)
printf '%s\n' "${scenes[@]}" | xargs -P 2 -I{} sh -c \
    "'$here/split.sh' '$bin' '$here/../scenes/{}.xml' $res $lo $hi > '$tmp/{}'"
for s in "${scenes[@]}"; do
    echo "== $s"
    cat "$tmp/$s"
done
rm -rf "$tmp"
