#!/usr/bin/env bash
# Instructions (callgrind) for one number from each of eight PCG32 streams: eight scalar
# steps against one AVX2 step (pcg8.rs, which first checks that both agree bit for bit),
# loop included, from (I(N=101000) - I(N=1000)) / 100000. Usage: bench/lanes/pcg8.sh
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
rustc -C opt-level=3 --edition 2021 "$here/pcg8.rs" -o "$tmp/pcg8"
count() {
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$tmp/pcg8" "$1" "$2" 2>&1 \
        | sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
for mode in scalar avx2; do
    a=$(count 1000 $mode) b=$(count 101000 $mode)
    python3 -c "print(f'$mode: {($b - $a) / 100000:.1f} instructions per 8 draws')"
done
rm -rf "$tmp"
