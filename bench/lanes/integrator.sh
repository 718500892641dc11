#!/usr/bin/env bash
# Instructions per camera path (callgrind, bench/lanes/ipp.sh) of `--integrator path` and
# `--integrator lanes` with one binary on issue 35's seven acceptance scenes, two scenes at
# a time, and their ratio (lanes ÷ path; below 1 the lanes integrator takes fewer).
# Usage: bench/lanes/integrator.sh BINARY [RES] [LO] [HI]
set -euo pipefail
bin=$1 res=${2:-48} lo=${3:-1} hi=${4:-5}
here=$(cd "$(dirname "$0")" && pwd)
scenes=(spot-point-room glossy-plates hdr-sky-sun thin-lens many-lights cornell-textured
    sun-sky-glass)
tmp=$(mktemp -d)
printf '%s\n' "${scenes[@]}" | xargs -P 2 -I{} sh -c \
    "p=\$('$here/ipp.sh' '$bin' '$here/../scenes/{}.xml' $res $lo $hi --integrator path);
     l=\$('$here/ipp.sh' '$bin' '$here/../scenes/{}.xml' $res $lo $hi --integrator lanes);
     echo \"\$p \$l\" > '$tmp/{}'"
printf '| scene | path | lanes | lanes ÷ path |\n|---|--:|--:|--:|\n'
for s in "${scenes[@]}"; do
    read -r p l < "$tmp/$s"
    python3 -c "print(f'| $s | $p | $l | {$l / $p:.3f} |')"
done
rm -rf "$tmp"
