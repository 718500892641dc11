#!/usr/bin/env bash
# Instructions per traversal query (callgrind, deterministic; unaffected by other load).
#   bench/traversal_ir.sh TRAVERSAL_BINARY SCENE [RAYS]   (default 65536 rays)
# Runs `traversal rays SCENE` under callgrind, counting only the timed loops
# (`trace_closest`, `trace_any`, and where the binary has them the packet loops
# `trace_closest8`, `trace_any8` and the shadow-ray loops), and prints each loop's
# inclusive instructions divided by the queries it made (each loop runs 3 passes).
set -euo pipefail
bin=$1 scene=$2 rays=${3:-65536}
tmp=$(mktemp -d)
valgrind --tool=callgrind --callgrind-out-file="$tmp/cg" \
    --toggle-collect='traversal::trace_*' "$bin" rays "$scene" "$tmp/out" "$rays" >"$tmp/log" 2>&1 \
    || { cat "$tmp/log"; exit 1; }
callgrind_annotate --inclusive=yes "$tmp/cg" 2>/dev/null \
    | sed -n 's/^ *\([0-9,]*\) ([ 0-9.]*%) *[^ ]*traversal::\(trace_[a-z0-9_]*\).*/\2 \1/p' \
    | sort -u -k1,1 \
    | while read -r name ir; do
        awk -v s="$scene" -v n="$name" -v ir="${ir//,/}" -v r="$rays" \
            'BEGIN { printf "%s %s %.1f\n", s, n, ir / (3 * r) }'
    done
rm -rf "$tmp"
